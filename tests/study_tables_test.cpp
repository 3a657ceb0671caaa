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

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "core/whole_file.hpp"
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
    CHECK(*row.mean_deviation_m == record["mean_deviation_m"].get<double>());
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

namespace {

// Every metric of `value` (at any depth) under its name moved to its legacy name in its legacy unit, as a
// record written before the metric table held it.
void to_legacy(nlohmann::json& value, std::size_t& moved) {
  if (value.is_array()) {
    for (nlohmann::json& element : value) to_legacy(element, moved);
    return;
  }
  if (!value.is_object()) return;
  for (const MetricInfo& info : metric_table()) {
    const std::string name(info.name);
    if (info.legacy_name.empty() || !value.contains(name)) continue;
    const nlohmann::json v = value[name];
    value.erase(name);
    value[std::string(info.legacy_name)] =
        v.is_null() ? v : nlohmann::json(v.get<double>() * info.legacy_factor);
    ++moved;
  }
  for (auto& member : value.items()) to_legacy(member.value(), moved);
}

std::vector<std::string> header(const std::string& csv) {
  std::vector<std::string> out;
  std::istringstream line(csv.substr(0, csv.find('\n')));
  for (std::string column; std::getline(line, column, ',');) out.push_back(column);
  return out;
}

}  // namespace

TEST_CASE("a record written before the metric table, its lengths in mm, gives the same rows",
          "[study][tables]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "legacy", "conditions": [{"name": "haptic", "mode": "haptic"}],
          "test": {"characters": ["十"], "conditions": ["haptic"], "repetitions": 1},
          "trial": {"max_duration_s": 40}})",
      "legacy.json");
  SessionSetup setup;
  setup.subject = {"S01", 1};
  setup.writer_seed = subject_seed("S01");
  SessionFolder session = SessionFolder::create(temp.path / "S01", setup, protocol);
  (void)run_session(session, study_test::run_options());
  const StudyTables now = read_study_tables({temp.path});
  REQUIRE(now.trials.size() == 1);
  const fs::path record_file =
      fs::path(now.trials[0].trace_file).replace_extension().replace_extension(".json");
  nlohmann::json record = read_json(record_file);
  std::size_t moved = 0;
  to_legacy(record, moved);
  REQUIRE(moved > 10);
  REQUIRE(record.contains("mean_deviation_mm"));
  REQUIRE_FALSE(record.contains("mean_deviation_m"));
  std::ofstream(record_file, std::ios::binary | std::ios::trunc) << record.dump(2);
  const StudyTables before = read_study_tables({temp.path});
  REQUIRE(before.trials.size() == 1);
  const auto same = [](const std::optional<double>& a, const std::optional<double>& b) {
    REQUIRE(a.has_value() == b.has_value());
    if (a) CHECK(*a == Approx(*b).epsilon(1e-15));
  };
  const TrialRow& a = now.trials[0];
  const TrialRow& b = before.trials[0];
  REQUIRE(a.mean_deviation_m.has_value());
  same(a.mean_deviation_m, b.mean_deviation_m);
  same(a.max_deviation_m, b.max_deviation_m);
  same(a.rms_deviation_m, b.rms_deviation_m);
  same(a.frechet_m, b.frechet_m);
  same(a.dtw_m, b.dtw_m);
  REQUIRE(now.strokes.size() == before.strokes.size());
  for (std::size_t i = 0; i < now.strokes.size(); ++i) {
    same(now.strokes[i].mean_deviation_m, before.strokes[i].mean_deviation_m);
    same(now.strokes[i].path_length_m, before.strokes[i].path_length_m);
    same(now.strokes[i].frechet_m, before.strokes[i].frechet_m);
  }
}

TEST_CASE("the tables' metric columns are the metric table's names", "[study][tables][metric]") {
  const StudyTables empty;
  const std::vector<std::string> trials = header(trials_csv(empty));
  const std::vector<std::string> strokes = header(strokes_csv(empty));
  const auto has = [](const std::vector<std::string>& columns, std::string_view name) {
    return std::find(columns.begin(), columns.end(), name) != columns.end();
  };
  for (const MetricInfo& info : metric_table()) {
    INFO(info.name);
    // every total of the scene is a column of the trials' table
    if (info.at(metric_level_scene)) CHECK(has(trials, info.name));
    // no column keeps a name the table retired
    if (!info.legacy_name.empty()) {
      CHECK_FALSE(has(trials, info.legacy_name));
      CHECK_FALSE(has(strokes, info.legacy_name));
    }
  }
  // every column with a unit suffix that names a metric names it as the table does, at the table's level
  for (const std::string& column : strokes) {
    const std::optional<MetricInfo> found = find_metric(column);
    if (found) {
      INFO(column);
      CHECK(found->name == column);
      CHECK(found->at(metric_level_stroke));
    }
  }
  CHECK(has(strokes, "mean_deviation_m"));
  CHECK(has(trials, "strokes_assisted"));
}

TEST_CASE("a folder without a session is named", "[study][tables]") {
  TempFolder temp;
  CHECK_THROWS_AS(read_study_tables({temp.path}), DataError);
  CHECK_THROWS_WITH(read_study_tables({temp.path}), Catch::Contains(temp.path.string()));
}
