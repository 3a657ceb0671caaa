// A study as tidy tables: one row per saved trial with its record's metrics in SI units, one row per
// reference stroke, CSV that quotes what needs quoting.
#include "calligraphy/study/study_tables.hpp"

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/protocol.hpp"
#include "core/whole_file.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"

using namespace calligraphy;
namespace fs = std::filesystem;

namespace {

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

std::size_t lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

}  // namespace

TEST_CASE("a study's tidy tables hold every saved trial with its record's metrics", "[study][tables]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "tables", "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
          "test": {"characters": ["十", "人"], "conditions": ["vision", "haptic"], "repetitions": 2},
          "trial": {"max_duration_s": 40}})",
      "tables.json");
  for (const char* id : {"S01", "S02"}) {
    SessionSetup setup;
    setup.subject = {id, 1};
    setup.writer_seed = subject_seed(id);
    SessionFolder session = SessionFolder::create(temp.path / id, setup, protocol);
    (void)run_session(session, study_test::run_options());
  }
  const StudyTables tables = read_study_tables({temp.path});
  REQUIRE(tables.trials.size() == 2 * 2 * 2 * 2);  // subjects x characters x conditions x repetitions
  std::size_t strokes = 0;
  for (const TrialRow& row : tables.trials) {
    INFO(row.trace_file.string());
    const nlohmann::json record =
        read_json(fs::path(row.trace_file).replace_extension().replace_extension(".json"));
    CHECK(row.subject == record["subject"].get<std::string>());
    CHECK(row.condition == record["condition"].get<std::string>());
    CHECK(row.repetition == record["repetition"].get<std::size_t>());  // 1-based in both
    CHECK(row.trial == record["trial"]["index"].get<std::size_t>());
    CHECK(row.block == record["trial"]["block"].get<std::size_t>());
    CHECK(row.item == record["trial"]["item"].get<std::size_t>());
    CHECK(row.trial >= 1);
    CHECK(row.block >= 1);
    CHECK(row.item >= 1);
    CHECK(row.strokes_total == record["strokes_total"].get<std::size_t>());
    REQUIRE(row.mean_deviation_m.has_value());
    CHECK(*row.mean_deviation_m == Approx(record["mean_deviation_mm"].get<double>() * 1e-3).epsilon(1e-12));
    CHECK(row.total_time_s == record["total_time_s"].get<double>());
    CHECK(fs::exists(row.trace_file));
    // The record binds its trace: the SHA-256 of the file's bytes as saved.
    CHECK(row.trace_sha256 == record["files"]["trace_sha256"].get<std::string>());
    CHECK(row.trace_sha256 == sha256_hex(read_regular_file(row.trace_file, 64u << 20)));
    strokes += row.strokes_total;
  }
  REQUIRE(tables.strokes.size() == strokes);
  for (const StrokeRow& row : tables.strokes) {
    CHECK(row.typical_id >= 1);
    CHECK(row.typical_id <= 39);
    if (row.written) CHECK(row.segments >= 1);
    CHECK(row.refused_segments <= row.segments);
  }
  // The CSV: a header and one line per row.
  CHECK(lines(trials_csv(tables)) == tables.trials.size() + 1);
  CHECK(lines(strokes_csv(tables)) == tables.strokes.size() + 1);
  CHECK(trials_csv(tables).rfind("subject,session,protocol,session_number,group,phase,block,condition", 0) ==
        0);
}

TEST_CASE("a table field with a comma or a quote is quoted, and a missing metric is empty",
          "[study][tables]") {
  StudyTables tables;
  TrialRow row;
  row.subject = "S01";
  row.trace_file = "/data/a,b \"c\".csv";
  tables.trials.push_back(row);
  const std::string csv = trials_csv(tables);
  CHECK(csv.find("\"/data/a,b \"\"c\"\".csv\"") != std::string::npos);
  CHECK(csv.find(",,,,,") != std::string::npos);  // the five absent deviations
}

TEST_CASE("a folder without a session is named", "[study][tables]") {
  TempFolder temp;
  CHECK_THROWS_AS(read_study_tables({temp.path}), DataError);
  CHECK_THROWS_WITH(read_study_tables({temp.path}), Catch::Contains(temp.path.string()));
}
