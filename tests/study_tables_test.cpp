// A study as tidy tables: one row per saved trial with its record's metrics in SI units, one row per
// reference stroke, CSV that quotes what needs quoting.
#include "calligraphy/study/study_tables.hpp"

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "core/whole_file.hpp"
#include "study/trial_row.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"
#include "written_share_metric.hpp"

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
    CHECK(row.metrics.at("strokes_total") == MetricValue(record["strokes_total"].get<std::int64_t>()));
    REQUIRE(row.metrics.number("mean_deviation_m").has_value());
    CHECK(*row.metrics.number("mean_deviation_m") == record["mean_deviation_m"].get<double>());
    CHECK(row.metrics.number("total_time_s") == record["total_time_s"].get<double>());
    CHECK(row.metrics.at("completed_in_order") == MetricValue(record["completed_in_order"].get<bool>()));
    CHECK(fs::exists(row.trace_file));
    // The record binds its trace: the SHA-256 of the file's bytes as saved.
    CHECK(row.trace_sha256 == record["files"]["trace_sha256"].get<std::string>());
    CHECK(row.trace_sha256 == sha256_hex(read_regular_file(row.trace_file, 64u << 20)));
    strokes += static_cast<std::size_t>(std::get<std::int64_t>(row.metrics.at("strokes_total")));
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
// record written before the metric table held it. The record's `specification` is not the metric table's: its
// fields (the acceptance's `mean_deviation_m`, ...) are named by its own schema, in every version.
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
  for (auto& member : value.items()) {
    if (member.key() != "specification") to_legacy(member.value(), moved);
  }
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
  REQUIRE(a.metrics.number("mean_deviation_m").has_value());
  for (const std::string_view name : a.metrics.names()) {
    INFO(name);
    same(a.metrics.number(name), b.metrics.number(name));
  }
  REQUIRE(now.strokes.size() == before.strokes.size());
  for (std::size_t i = 0; i < now.strokes.size(); ++i) {
    for (const std::string_view name : now.strokes[i].metrics.names()) {
      INFO(name);
      same(now.strokes[i].metrics.number(name), before.strokes[i].metrics.number(name));
    }
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

TEST_CASE("a metric added to the table as a trials column reaches the trials table and its rows",
          "[study][tables][metric]") {
  // A metric a project might add, one row of the metric table with its place among the trials table's
  // metric columns: the share of the reference strokes written, a number of the scene's totals.
  std::vector<MetricInfo> table(metric_table().begin(), metric_table().end());
  const std::vector<MetricInfo> before = study_metric_columns(StudyTable::trials, table);
  table.push_back(testing::written_share_metric(static_cast<std::uint8_t>(before.size() + 1)));
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "added", "conditions": [{"name": "haptic", "mode": "haptic"}],
          "test": {"characters": ["十"], "conditions": ["haptic"], "repetitions": 1},
          "trial": {"max_duration_s": 40}})",
      "added.json");
  SessionSetup setup;
  setup.subject = {"S01", 1};
  setup.writer_seed = subject_seed("S01");
  SessionFolder session = SessionFolder::create(temp.path / "S01", setup, protocol);
  (void)run_session(session, study_test::run_options());
  const StudyTables saved = read_study_tables({temp.path});
  REQUIRE(saved.trials.size() == 1);
  // the record as one written with the extended table holds it
  nlohmann::json record =
      read_json(fs::path(saved.trials[0].trace_file).replace_extension().replace_extension(".json"));
  const double share = record["strokes_written"].get<double>() / record["strokes_total"].get<double>();
  record["written_share"] = share;

  // the row read back holds it, by name
  StudyTables tables;
  tables.trials.push_back(study_detail::trial_row(record, "added.json", session.manifest(),
                                                  session.plan().at(0), tables.strokes, table));
  const TrialRow& row = tables.trials[0];
  CHECK(row.metrics.at("written_share") == MetricValue(share));
  CHECK(row.metrics.number("written_share") == share);
  CHECK(row.metrics.at("strokes_total") == saved.trials[0].metrics.at("strokes_total"));
  CHECK(tables.strokes.size() == saved.strokes.size());

  // the trials table's header has it after the metric columns before it, and the row its value there
  const std::string csv = trials_csv(tables, table);
  const std::vector<std::string> columns = header(csv);
  const auto at = std::find(columns.begin(), columns.end(), "written_share");
  REQUIRE(at != columns.end());
  CHECK(*(at - 1) == before.back().name);
  std::vector<std::string> fields;
  std::istringstream line(csv.substr(csv.find('\n') + 1));
  for (std::string field; std::getline(line, field, ',');) fields.push_back(field);
  REQUIRE(fields.size() >= columns.size());
  CHECK(std::stod(fields[static_cast<std::size_t>(at - columns.begin())]) == share);
  // every other column is as the library's table writes it
  std::vector<std::string> without = columns;
  without.erase(without.begin() + (at - columns.begin()));
  CHECK(without == header(trials_csv(saved)));
  // the strokes table has no place for it
  CHECK(header(strokes_csv(tables, table)) == header(strokes_csv(saved)));

  // a record written before it: an empty field (the metric table's default for a metric added later)
  record.erase("written_share");
  std::vector<StrokeRow> strokes;
  const TrialRow older =
      study_detail::trial_row(record, "older.json", session.manifest(), session.plan().at(0), strokes, table);
  CHECK(std::holds_alternative<std::monostate>(older.metrics.at("written_share")));
  // a record without one of the scoring's totals is damaged, and named
  record.erase("velocity_peaks");
  CHECK_THROWS_WITH(
      study_detail::trial_row(record, "damaged.json", session.manifest(), session.plan().at(0), strokes),
      Catch::Contains("damaged.json") && Catch::Contains("/velocity_peaks"));
  // the library's own table is untouched
  CHECK_FALSE(find_metric("written_share").has_value());
  CHECK_THROWS_AS(saved.trials[0].metrics.at("written_share"), InvalidArgument);
}

TEST_CASE("a folder without a session is named", "[study][tables]") {
  TempFolder temp;
  CHECK_THROWS_AS(read_study_tables({temp.path}), DataError);
  CHECK_THROWS_WITH(read_study_tables({temp.path}), Catch::Contains(temp.path.string()));
}
