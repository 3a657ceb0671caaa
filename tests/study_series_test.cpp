// A subject's series of sessions as a checked chain (calligraphy/study/session_series.hpp): the lock that
// serialises runs of one subject, and a predecessor whose clock was ahead, recorded as measured and read
// back by the manifest's own reader.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/study/session_series.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"

using namespace calligraphy;
namespace fs = std::filesystem;

TEST_CASE("a series lock makes a second run of the subject wait until the first ends", "[study][series]") {
  TempFolder temp;
  std::atomic<bool> acquired{false};
  std::atomic<int> waited{0};
  std::thread second;
  {
    const SeriesLock first(temp.path, "S01");
    CHECK(fs::is_directory(temp.path / "S01"));
    second = std::thread([&] {
      const SeriesLock lock(temp.path, "S01", [&](const fs::path& path) {
        CHECK(path == temp.path / "S01");
        ++waited;
      });
      acquired = true;
    });
    for (int i = 0; i < 200 && waited == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    CHECK(waited == 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    CHECK_FALSE(acquired);  // still held by the first
  }
  second.join();
  CHECK(acquired);
  // Another subject's series is not held up by this one's.
  const SeriesLock held(temp.path, "S01");
  bool other_waited = false;
  const SeriesLock other(temp.path, "S02", [&](const fs::path&) { other_waited = true; });
  CHECK_FALSE(other_waited);
}

TEST_CASE("a predecessor that ended after now is recorded as measured and read back", "[study][series]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "clock", "conditions": [{"name": "free", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
          "phases": [
            {"phase": "pre-test", "condition": "free", "characters": ["十"]},
            {"phase": "training", "condition": "fixture", "characters": ["十"]},
            {"phase": "post-test", "condition": "free", "characters": ["十"]},
            {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 60}],
          "trial": {"max_duration_s": 40}})",
      "clock.json");
  SessionSetup setup;
  setup.subject = {"S01", 1};
  setup.writer_seed = subject_seed("S01");
  fs::path first_folder;
  {
    SessionFolder first = SessionFolder::create(temp.path, setup, protocol);
    REQUIRE(run_session(first, study_test::run_options()).complete());
    first_folder = first.path();
  }
  // The last record's end from a clock 40 years ahead.
  fs::path last;
  for (const auto& entry : fs::directory_iterator(first_folder / "trials")) {
    if (entry.path().extension() == ".json" && (last.empty() || entry.path() > last)) last = entry.path();
  }
  std::stringstream text;
  text << std::ifstream(last).rdbuf();
  nlohmann::json record = nlohmann::json::parse(text.str());
  record["end_time_utc"] = "2066-01-01T00:00:00.000Z";
  std::ofstream(last) << record.dump();

  const SessionSeries series = session_series(temp.path, "S01", protocol);
  REQUIRE(series.previous);
  CHECK(series.ended_in_future());
  CHECK_FALSE(series.due());
  CHECK(series.previous_record == last);
  CHECK(series.previous->elapsed_s < -1e9);
  CHECK(series.previous->session_sha256.size() == 64);

  PreviousSession previous = *series.previous;
  previous.delay = SessionDelay::overridden;
  setup.session_number = 2;
  fs::path second_folder;
  {
    const SessionFolder second = SessionFolder::create(temp.path, setup, protocol, previous);
    second_folder = second.path();
  }
  // Its own reader takes what it wrote, and the series still links.
  const SessionFolder reopened = SessionFolder::open(second_folder);
  REQUIRE(reopened.manifest().previous);
  CHECK(reopened.manifest().previous->elapsed_s == previous.elapsed_s);
  CHECK(reopened.manifest().previous->session_sha256 == previous.session_sha256);
  CHECK(session_series(temp.path, "S01", protocol).unfinished == second_folder);
}
