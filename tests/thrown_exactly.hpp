#pragma once
// What the rounds that hold each documented throw to its exact type share: the message of the exception a
// call throws, and a substring check for it.
#include <catch2/catch.hpp>
#include <exception>
#include <string>
#include <typeinfo>

namespace calligraphy::testing {

// The message of the exception `call` throws, which must be of type E exactly (a CharacterNotFound is not
// accepted where the comment says DataError, nor the reverse). Fails the test when nothing or another type
// is thrown.
template <typename E, typename F>
std::string thrown_exactly(F&& call) {
  try {
    call();
  } catch (const std::exception& error) {
    INFO("thrown: " << typeid(error).name() << ": " << error.what());
    CHECK(typeid(error) == typeid(E));
    return error.what();
  }
  FAIL("nothing was thrown");
  return {};
}

inline bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace calligraphy::testing
