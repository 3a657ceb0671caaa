// for_each_item (calligraphy/core/worker_threads.hpp): every item done once whatever the threads, and the
// error of the lowest-numbered item that threw, the one a run in turn would meet first.
#include "calligraphy/core/worker_threads.hpp"

#include <atomic>
#include <catch2/catch.hpp>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

using calligraphy::for_each_item;

TEST_CASE("for_each_item does every item exactly once on any number of threads", "[worker_threads]") {
  for (const std::size_t threads : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{7}}) {
    for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{200}}) {
      std::vector<std::atomic<int>> done(count);
      const std::size_t ran = for_each_item(count, threads, [&done](std::size_t i) { ++done[i]; });
      for (std::size_t i = 0; i < count; ++i) REQUIRE(done[i].load() == 1);
      REQUIRE(ran >= 1);
      REQUIRE(ran <= std::max<std::size_t>(1, count));
      if (threads > 0) REQUIRE(ran <= threads);
    }
  }
}

TEST_CASE("for_each_item rethrows the lowest-numbered item's error and starts no item after one threw",
          "[worker_threads]") {
  for (const std::size_t threads : {std::size_t{1}, std::size_t{2}, std::size_t{4}}) {
    std::vector<std::atomic<int>> done(100);
    try {
      (void)for_each_item(100, threads, [&done](std::size_t i) {
        ++done[i];
        // Items 60 and 30 both fail; 60 may be taken first on another thread, 30 is still the one named.
        if (i == 30 || i == 60) throw std::runtime_error("item " + std::to_string(i));
      });
      FAIL("no exception");
    } catch (const std::runtime_error& e) {
      REQUIRE(std::string(e.what()) == "item 30");
    }
    for (std::size_t i = 0; i <= 30; ++i)
      REQUIRE(done[i].load() == 1);  // taken in order, each run to its end
    // On one thread nothing after the failed item starts; on more, the others stop at their next take.
    if (threads == 1) {
      for (std::size_t i = 31; i < 100; ++i) REQUIRE(done[i].load() == 0);
    }
  }
}
