#include "devices/log_queue.hpp"

#include <catch2/catch.hpp>
#include <thread>
#include <vector>

// Named in full: the servo programs are built a few files to a unit, where calligraphy has a SpscQueue
// and a LogLevel of its own.

TEST_CASE("The SPSC queue returns records in the order they were pushed", "[log_queue][servo]") {
  calligraphy::devices::SpscQueue<int, 8> queue;
  int out = -1;
  CHECK_FALSE(queue.try_pop(out));
  for (int round = 0; round < 5; ++round) {  // several laps around the ring
    for (int i = 0; i < 6; ++i) REQUIRE(queue.try_push(round * 10 + i));
    CHECK(queue.size() == 6);
    for (int i = 0; i < 6; ++i) {
      REQUIRE(queue.try_pop(out));
      CHECK(out == round * 10 + i);
    }
    CHECK_FALSE(queue.try_pop(out));
  }
  CHECK(queue.dropped() == 0);
}

TEST_CASE("A full SPSC queue drops the newest record and counts it", "[log_queue][servo]") {
  calligraphy::devices::SpscQueue<int, 4> queue;
  for (int i = 0; i < 4; ++i) REQUIRE(queue.try_push(i));
  CHECK_FALSE(queue.try_push(99));
  CHECK_FALSE(queue.try_push(100));
  CHECK(queue.dropped() == 2);
  int out = -1;
  REQUIRE(queue.try_pop(out));
  CHECK(out == 0);
  REQUIRE(queue.try_push(4));  // room again after one pop
  std::vector<int> rest;
  while (queue.try_pop(out)) rest.push_back(out);
  CHECK(rest == std::vector<int>{1, 2, 3, 4});
}

TEST_CASE("One producer and one consumer thread pass every record in order", "[log_queue][servo]") {
  calligraphy::devices::SpscQueue<std::uint64_t, 64> queue;
  constexpr std::uint64_t kCount = 50000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount;) {
      if (queue.try_push(i)) {
        ++i;
      } else {
        std::this_thread::yield();  // full: let the consumer run (spinning is slow under TSan)
      }
    }
  });
  std::uint64_t expected = 0;
  bool in_order = true;
  while (expected < kCount) {
    std::uint64_t value = 0;
    if (!queue.try_pop(value)) {
      std::this_thread::yield();
      continue;
    }
    in_order = in_order && value == expected;
    ++expected;
  }
  producer.join();
  CHECK(in_order);
  CHECK(queue.size() == 0);
}

TEST_CASE("The log drain hands every record to the sink in order, also those left at stop",
          "[log_queue][servo]") {
  calligraphy::devices::LogQueue queue;
  std::vector<std::uint64_t> seen;  // touched only by the drain thread until stop() joins it
  calligraphy::devices::LogDrain drain;
  drain.start(
      queue, [&](const calligraphy::devices::LogRecord& r) { seen.push_back(r.count); },
      std::chrono::milliseconds(1));
  for (std::uint64_t i = 0; i < 1000; ++i) {
    calligraphy::devices::LogRecord r;
    r.code = 7;
    r.count = i;
    r.set_text("a message longer than nothing");
    while (!queue.try_push(r)) std::this_thread::yield();
  }
  drain.stop();
  REQUIRE(seen.size() == 1000);
  for (std::uint64_t i = 0; i < seen.size(); ++i) REQUIRE(seen[i] == i);
}

TEST_CASE("A log record truncates a long text and keeps it NUL-terminated", "[log_queue][servo]") {
  calligraphy::devices::LogRecord r;
  const std::string long_text(500, 'x');
  r.set_text(long_text.c_str());
  CHECK(std::string(r.text.data()) == std::string(r.text.size() - 1, 'x'));
  r.set_text(nullptr);
  CHECK(r.text[0] == '\0');
}
