#pragma once
// What the protocol tests share: an error's file and JSON pointer checked, and subject ids by number.
#include <catch2/catch.hpp>
#include <cstddef>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/protocol.hpp"

namespace protocol_checks {

/// Parsing `text` as "p.json" fails with a ProtocolError (the command line's usage error) at `pointer` whose
/// message contains `words`.
inline void check_error(const std::string& text, const std::string& pointer, const std::string& words) {
  try {
    (void)calligraphy::parse_study_protocol(text, "p.json");
    FAIL("no error for " << text);
  } catch (const calligraphy::ProtocolError& e) {
    const std::string message = e.what();
    CHECK_THAT(message, Catch::StartsWith("p.json: " + pointer + ": "));
    CHECK_THAT(message, Catch::Contains(words));
  }
}

/// "S" followed by the number (appended: GCC 12 warns wrongly about `"S" + std::to_string(n)` at -O3).
inline std::string subject_id(std::size_t number) {
  std::string id = "S";
  id.append(std::to_string(number));
  return id;
}

}  // namespace protocol_checks
