// The one table of a trial's results (calligraphy/analysis/metric_table.hpp): every name carries its unit,
// the metrics record (what `trial --json`, `score --json`, trial and study records and Python carry) has
// exactly the table's metrics at each level with the values of the scoring, and a metric added to the table
// (a test-only one here) reaches the record, the docs' table and the JSON Schema with nothing else written
// for it. The same for a field added to a struct's schema: `where to add` of docs/architecture.md.
#include "calligraphy/analysis/metric_table.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/report/score_report.hpp"
#include "embedded_scenes.hpp"
#include "report/metrics_object.hpp"
#include "report/trial_outcome.hpp"
#include "written_share_metric.hpp"

using namespace calligraphy;

namespace {

bool ends_with(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

// The unit as a name spells it: "m" -> "_m", "m/s" -> "_m_s", "N" -> "_n".
std::string suffix_of(std::string_view unit) {
  std::string out = "_";
  for (const char c : unit)
    out += c == '/' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// 十 written along its strokes' centre lines, 0.3 mm to the side, at 1 kHz; the pen lifted between strokes.
WritingMetrics scored_character() {
  const Scene& scene = testing::embedded_scene(U'十');
  std::vector<PenSample> trace;
  double t = 0.0;
  for (const PlacedStroke& stroke : scene.characters.front().strokes) {
    for (const Vec2& p : reference_polyline_m(stroke.elements, 0.2e-3, 4096)) {
      trace.push_back({t, p + Vec2(0.0, 0.3e-3), true});
      t += 1e-3;
    }
    trace.push_back({t, trace.back().position_m, false});
    t += 0.2;
  }
  return writing_metrics(scene, trace);
}

std::set<std::string> keys(const nlohmann::json& object) {
  std::set<std::string> out;
  for (const auto& item : object.items()) out.insert(item.key());
  return out;
}

std::set<std::string> table_names(MetricLevel level, std::span<const MetricInfo> table = metric_table()) {
  std::set<std::string> out;
  for (const MetricInfo& info : table)
    if (info.at(level)) out.emplace(info.name);
  return out;
}

}  // namespace

TEST_CASE("every metric has one name with its SI unit in it", "[metric]") {
  std::set<std::string_view> names;
  for (const MetricInfo& info : metric_table()) {
    INFO(info.name);
    CHECK(names.insert(info.name).second);
    if (!info.legacy_name.empty()) CHECK(names.insert(info.legacy_name).second);
    CHECK_FALSE(info.doc.empty());
    CHECK_FALSE(info.definition.empty());
    CHECK(info.levels != 0);
    if (!info.unit.empty()) {
      CHECK(info.kind == MetricKind::number);
      CHECK(ends_with(info.name, suffix_of(info.unit)));
    }
    CHECK_FALSE(ends_with(info.name, "_mm"));
    if (!info.legacy_name.empty()) {  // the old names were millimetres
      CHECK(ends_with(info.legacy_name, "_mm"));
      CHECK(info.legacy_factor == 1e3);
      CHECK(info.unit == "m");
    }
    // a value at every level it is reported at (the run's come from the renderer's figures)
    CHECK((info.of_scene != nullptr) == info.at(metric_level_scene));
    CHECK((info.of_character != nullptr) == info.at(metric_level_character));
    CHECK((info.of_stroke != nullptr) == info.at(metric_level_stroke));
  }
  CHECK(find_metric("mean_deviation_mm")->name == "mean_deviation_m");
  CHECK_FALSE(find_metric("mean_deviation").has_value());
  CHECK_THROWS_AS(metric("frechet_mm"), InvalidArgument);
}

TEST_CASE("the metrics record holds the table's metrics at each level, in SI units", "[metric]") {
  const WritingMetrics scored = scored_character();
  const nlohmann::json record = nlohmann::json::parse(writing_metrics_json(scored));
  std::set<std::string> scene = table_names(metric_level_scene);
  scene.insert({"refusals", "per_character"});
  CHECK(keys(record) == scene);
  const nlohmann::json& character = record["per_character"][0];
  std::set<std::string> per_character = table_names(metric_level_character);
  per_character.insert({"character", "refusals", "missing_strokes", "per_stroke", "segments"});
  CHECK(keys(character) == per_character);
  std::set<std::string> per_stroke = table_names(metric_level_stroke);
  per_stroke.insert({"index", "typical_id"});
  REQUIRE(character["per_stroke"].size() == 2);
  for (const nlohmann::json& stroke : character["per_stroke"]) CHECK(keys(stroke) == per_stroke);

  // the values are the scoring's, lengths in metres: the horizontal stroke 0.3 mm beside itself, the vertical
  // one along its own line
  REQUIRE(scored.deviation.has_value());
  CHECK(record["mean_deviation_m"].get<double>() == scored.deviation->mean_m);
  CHECK(record["max_deviation_m"].get<double>() == Approx(0.3e-3).margin(0.02e-3));
  CHECK(character["per_stroke"][0]["mean_deviation_m"].get<double>() == Approx(0.3e-3).margin(0.02e-3));
  CHECK(record["frechet_m"].get<double>() == *scored.frechet_m);
  CHECK(character["path_length_m"].get<double>() == scored.characters[0].totals.path_length_m);
  CHECK(character["per_stroke"][1]["dtw_m"].get<double>() ==
        scored.characters[0].strokes[1].metrics->curves.dtw_m);
  CHECK(record["strokes_written"] == 2);
  CHECK(record["completed_in_order"] == true);
}

TEST_CASE("every run-level metric has the renderer's value in a trial's record", "[metric]") {
  TrialMetrics run;
  run.strokes_completed = 3;
  run.strokes_assisted = 1;
  run.time_s = 2.5;
  run.max_force_n = 1.25;
  run.max_force_step_n = 0.5;
  run.state_transitions = 7;
  run.readings_rejected = 4;
  std::set<std::string> seen;
  for (const MetricInfo& info : metric_table()) {
    const MetricValue value = report_detail::run_metric_value(info, run);
    INFO(info.name);
    CHECK(std::holds_alternative<std::monostate>(value) == !info.at(metric_level_run));
    if (info.at(metric_level_run)) seen.emplace(info.name);
  }
  CHECK(seen == std::set<std::string>{"strokes_completed", "strokes_assisted", "trial_time_s", "max_force_n",
                                      "max_force_step_n", "state_transitions", "readings_rejected"});
  const auto rejected = std::find_if(metric_table().begin(), metric_table().end(),
                                     [](const MetricInfo& info) { return info.name == "readings_rejected"; });
  REQUIRE(rejected != metric_table().end());
  CHECK(std::get<std::int64_t>(report_detail::run_metric_value(*rejected, run)) == 4);
}

// ---- where to add: a metric, a struct's field

namespace {

// A metric a project might add: the strokes written twice as fast as the reference's ... here simply the
// count of strokes never written, from the scoring, at the character level.
std::vector<MetricInfo> table_with_added_metric() {
  std::vector<MetricInfo> table(metric_table().begin(), metric_table().end());
  table.push_back({.name = "strokes_left_out",
                   .kind = MetricKind::count,
                   .doc = "reference strokes never written",
                   .definition = "size of `CharacterScore::missing_strokes`",
                   .levels = metric_level_character,
                   .of_character = [](const CharacterScore& c) {
                     return MetricValue(static_cast<std::int64_t>(c.missing_strokes.size()));
                   }});
  return table;
}

// A struct with a schema as trial parameters have (trial_spec.hpp), and one field added to it.
struct Extended {
  double rate_hz = 1000.0;
  double settle_time_s = 0.125;  // the added field
};

}  // namespace

template <>
struct calligraphy::SchemaOf<Extended> {
  static const Schema& get() {
    static const SchemaField fields[] = {
        number_field<&Extended::rate_hz>("rate_hz", {.low = 100.0, .high = 1e5},
                                         {.unit = "Hz", .doc = "servo rate", .option = "--rate"}),
        // the one row added: everything below reaches it with nothing else written
        since(2, number_field<&Extended::settle_time_s>(
                     "settle_time_s", {.low = 0.0, .high = 10.0},
                     {.unit = "s", .doc = "time the pen rests before the trial", .option = "--settle-time"})),
    };
    static const Schema schema{.name = "Extended",
                               .doc = "a struct with an added field",
                               .fields = fields,
                               .defaults = default_of<Extended>};
    return schema;
  }
};

TEST_CASE("a metric added to the table reaches the record, the docs' table and the JSON Schema", "[metric]") {
  const std::vector<MetricInfo> table = table_with_added_metric();
  // 十 written without its second stroke
  const Scene& scene = testing::embedded_scene(U'十');
  std::vector<PenSample> trace;
  double t = 0.0;
  for (const Vec2& p : reference_polyline_m(scene.characters.front().strokes[0].elements, 0.2e-3, 4096)) {
    trace.push_back({t, p, true});
    t += 1e-3;
  }
  const WritingMetrics scored = writing_metrics(scene, trace);
  nlohmann::json character;
  report_detail::add_metrics(character, metric_level_character, scored.characters[0], table);
  CHECK(character["strokes_left_out"] == 1);
  CHECK(character["strokes_written"] == 1);
  // read back by its name
  const std::optional<MetricInfo> found = find_metric("strokes_left_out", table);
  REQUIRE(found.has_value());
  CHECK(character[std::string(found->name)].get<std::int64_t>() == 1);
  CHECK_FALSE(find_metric("strokes_left_out").has_value());  // the library's own table is untouched
  // the docs' table row and the JSON Schema property
  CHECK_THAT(
      metric_markdown(table),
      Catch::Contains("| `strokes_left_out` | count | - | character | reference strokes never written | "
                      "size of `CharacterScore::missing_strokes` |  |"));
  CHECK_FALSE(metric_markdown(table) == metric_markdown());
  const nlohmann::json schema = nlohmann::json::parse(metric_json_schema(metric_level_character, table));
  CHECK(schema["properties"]["strokes_left_out"]["type"] == "integer");
  CHECK(schema["properties"]["strokes_left_out"]["description"] == "reference strokes never written");
  CHECK(schema["properties"].size() == table_names(metric_level_character, table).size());
  const nlohmann::json scene_schema = nlohmann::json::parse(metric_json_schema(metric_level_scene, table));
  CHECK_FALSE(scene_schema["properties"].contains("strokes_left_out"));
}

TEST_CASE("the study tables' metric columns have one place each, at their table's level", "[metric]") {
  for (const StudyTable which : {StudyTable::trials, StudyTable::strokes}) {
    const std::vector<MetricInfo> columns = study_metric_columns(which);
    REQUIRE_FALSE(columns.empty());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      INFO(columns[i].name);
      CHECK(columns[i].column(which) == i + 1);  // places 1, 2, 3, ...: none twice, none left out
      if (which == StudyTable::trials)
        CHECK((columns[i].at(metric_level_scene) || columns[i].at(metric_level_run)));
      else
        CHECK(columns[i].at(metric_level_stroke));
    }
    // a row without values yet: every column, a number null, a count 0, a flag false
    const MetricValues row(which);
    REQUIRE(row.names().size() == columns.size());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      CHECK(row.names()[i] == columns[i].name);
      CHECK(row.values()[i].index() == (columns[i].kind == MetricKind::number  ? 0u
                                        : columns[i].kind == MetricKind::count ? 2u
                                                                               : 3u));
    }
  }
  // the scoring's totals a record always holds are refused when missing; metrics added later read as null
  CHECK(metric("total_time_s").if_missing == MetricMissing::refused);
  CHECK(metric("mean_deviation_m").if_missing == MetricMissing::null);

  // a metric added with a place among the trials columns is one of them, in its place, and a row holds it
  std::vector<MetricInfo> table(metric_table().begin(), metric_table().end());
  const std::size_t before = study_metric_columns(StudyTable::trials, table).size();
  table.push_back(testing::written_share_metric(static_cast<std::uint8_t>(before + 1)));  // after the others
  const std::vector<MetricInfo> columns = study_metric_columns(StudyTable::trials, table);
  REQUIRE(columns.size() == before + 1);
  CHECK(columns.back().name == "written_share");
  CHECK(columns[before - 1].name == study_metric_columns(StudyTable::trials).back().name);
  CHECK(study_metric_columns(StudyTable::strokes, table).size() ==
        study_metric_columns(StudyTable::strokes).size());
  MetricValues row(StudyTable::trials, table);
  CHECK_FALSE(row.number("written_share").has_value());
  row.set("written_share", 0.5);
  CHECK(row.number("written_share") == 0.5);
  row.set("strokes_total", std::int64_t{4});
  CHECK(row.number("strokes_total") == 4.0);
  CHECK_THROWS_WITH(row.at("no_such_metric"), Catch::Contains("no_such_metric"));
  CHECK_THROWS_AS(MetricValues(StudyTable::trials).at("written_share"), InvalidArgument);
}

TEST_CASE(
    "a field added to a struct's schema reaches its option, JSON both ways, the docs' table and the "
    "JSON Schema",
    "[metric][schema]") {
  const Schema& schema = SchemaOf<Extended>::get();
  const SchemaField* added = schema.field("--settle-time");
  REQUIRE(added != nullptr);
  // the command line: what `calligraphy ... --help` prints for it (cli/app.cpp: doc [unit], range) and its
  // value from text
  CHECK(added->description() == "time the pen rests before the trial [s], in [0, 10] s");
  Extended e;
  set_field_from_text(*added, &e, "0.5");
  CHECK(e.settle_time_s == 0.5);
  CHECK(field_text(*added, &e) == "0.5");
  // JSON both ways; an older document without it takes the default and says so
  const nlohmann::json written = nlohmann::json::parse(schema_json(e));
  CHECK(written["settle_time_s"] == 0.5);
  CHECK(schema_from_json<Extended>(written.dump(), "e.json").settle_time_s == 0.5);
  Extended old;
  const SchemaReadResult read =
      schema_from_json(schema, &old, R"({"rate_hz": 500})", "old.json", {.require_all = true, .version = 1});
  CHECK(read.defaulted == std::vector<std::string>{"/settle_time_s"});
  CHECK(old.settle_time_s == 0.125);
  CHECK_THROWS_WITH(schema_from_json<Extended>(R"({"settle_time_s": 11})", "bad.json"),
                    Catch::Contains("bad.json") && Catch::Contains("/settle_time_s"));
  // the docs' table and the JSON Schema
  CHECK_THAT(schema_markdown(schema),
             Catch::Contains("| `settle_time_s` | number | s | in [0, 10] s | `0.125` |"));
  const nlohmann::json json_schema =
      nlohmann::json::parse(json_schema_text(schema, "https://calligraphy.invalid/e.json", "Extended", true));
  CHECK(json_schema["properties"]["settle_time_s"]["maximum"] == 10.0);
  CHECK(json_schema["properties"]["settle_time_s"]["default"] == 0.125);
  CHECK(json_schema["required"] == nlohmann::json::array({"rate_hz"}));
}
