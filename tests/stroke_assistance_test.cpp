// No dead end: refused attempts at a stroke are counted; after hint_after_misses the stroke is shown as a
// hint, after assist_after_misses it is credited as assisted (not written) and the next stroke is active
// (StrokeAcceptance, active_stroke.hpp). The recorder, a trial's record and its replay keep the credits.
#include <algorithm>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/collision/active_stroke.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "study_test_devices.hpp"

using namespace calligraphy;

namespace {

// The stroke's centre line from its start up to `fraction` of its points, in steps of at most 0.25 mm.
std::vector<Vec2> along_line(const PlacedStroke& stroke, double fraction) {
  const std::vector<Vec2>& line = stroke.centre_line.points_m;
  const auto last = static_cast<std::size_t>(fraction * static_cast<double>(line.size() - 1));
  std::vector<Vec2> out{line.front()};
  for (std::size_t k = 1; k <= last; ++k) {
    const int steps = std::max(1, static_cast<int>((line[k] - line[k - 1]).norm() / 0.25e-3));
    for (int i = 1; i <= steps; ++i)
      out.push_back(line[k - 1] + (line[k] - line[k - 1]) * (i / double(steps)));
  }
  return out;
}

void attempt(ActiveStroke& active, double fraction) {
  const std::vector<Vec2> path = along_line(*active.stroke(), fraction);
  active.begin(path.front());
  for (const Vec2& p : path) active.advance(p);
}

// An attempt that enters the stroke at its start and lifts a fifth of the way along: too short.
void short_attempt(ActiveStroke& active) { attempt(active, 0.2); }

// The whole stroke along its centre line.
void whole_attempt(ActiveStroke& active) { attempt(active, 1.0); }

}  // namespace

TEST_CASE(
    "Refused attempts are counted per stroke: a hint after hint_after_misses, assisted credit after "
    "assist_after_misses",
    "[stroke_assistance]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  StrokeAcceptance acceptance;
  acceptance.hint_after_misses = 2;
  acceptance.assist_after_misses = 4;
  ActiveStroke active(scene, acceptance);
  for (std::uint32_t miss = 1; miss <= 3; ++miss) {
    short_attempt(active);
    const StrokeProgress lifted = active.lift();
    CHECK_FALSE(lifted.stroke_completed);
    CHECK_FALSE(lifted.stroke_assisted);
    CHECK(lifted.refusal == StrokeRefusal::too_short);
    CHECK(active.misses() == miss);
    CHECK(active.hint_shown() == (miss >= 2));
    CHECK(active.stroke_index() == 0);
  }
  short_attempt(active);
  const StrokeProgress fourth = active.lift();
  CHECK(fourth.stroke_assisted);
  CHECK_FALSE(fourth.stroke_completed);
  CHECK(active.stroke_index() == 1);  // the next stroke is active, with no misses and no hint
  CHECK(active.misses() == 0);
  CHECK_FALSE(active.hint_shown());
  CHECK(active.strokes_assisted() == 1);
  CHECK(active.strokes_written() == 0);
  // A written stroke is written, not assisted; its misses are forgotten with it.
  short_attempt(active);
  (void)active.lift();
  CHECK(active.misses() == 1);
  whole_attempt(active);
  (void)active.lift();
  CHECK(active.finished());
  CHECK(active.strokes_written() == 1);
  CHECK(active.strokes_assisted() == 1);
}

TEST_CASE("With assist_after_misses 0 a stroke is never credited, with hint_after_misses 0 never hinted",
          "[stroke_assistance]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  StrokeAcceptance acceptance;
  acceptance.hint_after_misses = 0;
  acceptance.assist_after_misses = 0;
  ActiveStroke active(scene, acceptance);
  for (int miss = 1; miss <= 50; ++miss) {
    short_attempt(active);
    CHECK_FALSE(active.lift().stroke_assisted);
  }
  CHECK(active.misses() == 50);
  CHECK_FALSE(active.hint_shown());
  CHECK(active.stroke_index() == 0);
}

TEST_CASE("A miss count that is not a whole number is refused by name", "[stroke_assistance]") {
  StrokeAcceptance acceptance;
  acceptance.assist_after_misses = 2.5;
  CHECK_THROWS_WITH(acceptance.validate(), Catch::Contains("assist_after_misses"));
  acceptance.assist_after_misses = 5;
  acceptance.hint_after_misses = -1;
  CHECK_THROWS_WITH(acceptance.validate(), Catch::Contains("hint_after_misses"));
}

TEST_CASE("The recorder counts an assisted stroke apart from the strokes written", "[stroke_assistance]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  TrialRecorder recorder(scene);
  DeviceState state;
  RenderOutput out;
  out.state = InteractionState::writing;
  out.state_changed = true;
  state.time_s = 0.1;
  recorder.record(state, out);
  out.state = InteractionState::separation;
  out.stroke_abandoned = true;
  out.stroke_assisted = true;
  state.time_s = 0.2;
  recorder.record(state, out);
  recorder.finish(0.3);
  const TrialMetrics& m = recorder.metrics();
  CHECK(m.strokes_assisted == 1);
  CHECK(m.strokes_completed == 0);
  CHECK(m.per_stroke[0].assisted);
  CHECK_FALSE(m.per_stroke[0].completed);
  CHECK_FALSE(m.per_stroke[1].assisted);
  CHECK_FALSE(m.completed_in_order);
}

TEST_CASE(
    "A trial whose writer always lifts mid-stroke ends with its strokes assisted, and its record "
    "replays the same credits",
    "[stroke_assistance]") {
  // 人: every element is 20 mm or longer, so a lift at 30-70 % of a stroke is refused (too short); with no
  // correction between attempts the writer does that every time.
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  TrialSpec spec;
  spec.characters = "人";
  spec.writer_parameters = {
      {"mid_stroke_lift_probability", 1.0}, {"correction_per_attempt", 0.0}, {"max_attempts_per_stroke", 20}};
  spec.seed = 3;
  spec.max_duration_s = 120.0;
  SimulatedWriting writing(spec);
  const TrialRun first =
      run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
  const TrialMetrics& m = first.result.metrics;
  REQUIRE(m.strokes_total == 2);
  CHECK(m.strokes_assisted == 2);
  CHECK(m.strokes_completed == 0);
  for (const StrokeMetrics& s : m.per_stroke) CHECK(s.assisted);
  // The first stroke's misses are all lifts in WS. The writer redoes a stroke it saw cleared even when it was
  // credited in the same tick: it touches down once more at the first stroke's start, a pen-down off the
  // second's start that is a miss of the second (StrokeAcceptance::counts_as_miss), so the second has fewer
  // attempts in WS (`attempts` counts those) than misses.
  CHECK(m.per_stroke[0].attempts == static_cast<int>(StrokeAcceptance{}.assist_after_misses));
  CHECK(m.per_stroke[1].attempts <= static_cast<int>(StrokeAcceptance{}.assist_after_misses));
  CHECK(first.result.end == TrialEnd::completed);  // no dead end: the trial went on to its end

  const std::string json = recorded_trial_json(recorded_trial(spec, first, writing, scene));
  CHECK(nlohmann::json::parse(json)["version"] == kRecordedTrialVersion);
  const RecordedTrial recorded = read_recorded_trial(json, "r.json");
  CHECK(recorded.force_law.acceptance == first.options.force.acceptance);
  SimulatedWriting again_writing = recorded_writing(recorded);
  const TrialRun again = rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), scene,
                                     study_test::trial_inputs(&again_writing));
  REQUIRE(again.result.metrics.per_stroke.size() == m.per_stroke.size());
  CHECK(again.result.metrics.strokes_assisted == m.strokes_assisted);
  for (std::size_t i = 0; i < m.per_stroke.size(); ++i) {
    CHECK(again.result.metrics.per_stroke[i].assisted == m.per_stroke[i].assisted);
    CHECK(again.result.metrics.per_stroke[i].attempts == m.per_stroke[i].attempts);
  }
  CHECK(again.result.trace.size() == first.result.trace.size());

  // A version-3 record (no miss counts, no growing tolerances) runs as it ran: no stroke is assisted.
  nlohmann::json old = nlohmann::json::parse(json);
  old["version"] = 3;
  for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields())
    old["trial"].erase(std::string(field.name));
  for (const char* key :
       {"shortfall_per_length", "shortfall_cap_m", "deviation_per_length", "mean_deviation_cap_m",
        "reference_character_size_m", "hint_after_misses", "assist_after_misses"}) {
    old["force_law"]["acceptance"].erase(key);
  }
  const RecordedTrial v3 = read_recorded_trial(old.dump(), "v3.json");
  CHECK(v3.force_law.acceptance.assist_after_misses == 0.0);
  CHECK(v3.force_law.acceptance.shortfall_per_length == 0.0);
  CHECK(v3.force_law.acceptance.end_gap_m == 0.0);
  CHECK(v3.spec.acceptance == v3.force_law.acceptance);  // the specification states what ran

  // A version-4 record (no floor of the end gap) runs as it ran: without the floor, the rest as recorded.
  nlohmann::json v4_json = nlohmann::json::parse(json);
  v4_json["version"] = 4;
  for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields())
    v4_json["trial"].erase(std::string(field.name));
  for (const char* key : {"end_gap_m", "end_gap_fraction"}) v4_json["force_law"]["acceptance"].erase(key);
  const RecordedTrial v4 = read_recorded_trial(v4_json.dump(), "v4.json");
  StrokeAcceptance as_v4 = first.options.force.acceptance;
  as_v4.use_version_4_end_gaps();
  as_v4.use_version_6_coverage();
  as_v4.use_version_7_misses();
  CHECK(v4.force_law.acceptance == as_v4);
  CHECK(v4.force_law.acceptance.end_gap_m == 0.0);
  CHECK(recorded.force_law.acceptance.end_gap_m == StrokeAcceptance{}.end_gap_m);
  // Without the floor, a stroke left 4 mm short at one end of a 10 mm stroke is refused; with it, accepted.
  CHECK(as_v4.allowed_end_gap_m(0.010) < 0.004);
  CHECK(StrokeAcceptance{}.allowed_end_gap_m(0.010) >= 0.004);
}

namespace {

// 人 written by a writer that always lifts mid-stroke and never corrects (as above), by the options of
// `calligraphy trial` and `extra` after them.
TrialSpec always_missing(std::vector<std::string> extra) {
  std::vector<std::string> args{"人",
                                "--writer-param",
                                "mid_stroke_lift_probability=1",
                                "--writer-param",
                                "correction_per_attempt=0",
                                "--writer-param",
                                "max_attempts_per_stroke=20",
                                "--seed",
                                "3",
                                "--max-duration",
                                "120"};
  args.insert(args.end(), extra.begin(), extra.end());
  return *trial_spec_from_args(args);
}

TrialRun run_spec(const TrialSpec& spec, const Scene& scene) {
  SimulatedWriting writing(spec);
  return run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
}

}  // namespace

TEST_CASE(
    "The specification's miss counts reach the renderer: --assist-after-misses 1 assists each stroke after "
    "one miss, sooner than the default",
    "[stroke_assistance]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  const TrialSpec by_default = always_missing({});
  const TrialSpec sooner = always_missing({"--assist-after-misses", "1", "--hint-after-misses", "0"});
  CHECK(sooner.acceptance.assist_after_misses == 1.0);
  CHECK(sooner.acceptance.hint_after_misses == 0.0);
  CHECK(trial_options(Checked<TrialSpec>::check(sooner), DeviceInfo{}).force.acceptance == sooner.acceptance);

  const TrialRun first = run_spec(by_default, scene);
  const TrialRun quick = run_spec(sooner, scene);
  CHECK(quick.options.force.acceptance.assist_after_misses == 1.0);
  REQUIRE(quick.result.metrics.per_stroke.size() == 2);
  REQUIRE(first.result.metrics.per_stroke.size() == 2);
  CHECK(quick.result.metrics.strokes_assisted == 2);
  for (std::size_t i = 0; i < 2; ++i) CHECK(quick.result.metrics.per_stroke[i].assisted);
  // The second stroke's misses may include a pen-down off its start (the writer redoing the first): no more
  // attempts in WS than misses.
  CHECK(quick.result.metrics.per_stroke[0].attempts == 1);
  CHECK(quick.result.metrics.per_stroke[1].attempts <= 1);
  CHECK(first.result.metrics.per_stroke[0].attempts ==
        static_cast<int>(StrokeAcceptance{}.assist_after_misses));
  CHECK(first.result.metrics.per_stroke[1].attempts <=
        static_cast<int>(StrokeAcceptance{}.assist_after_misses));
  CHECK(quick.result.end == TrialEnd::completed);
  // Fewer attempts: the trial is over sooner.
  CHECK(quick.result.trace.size() < first.result.trace.size());
}

TEST_CASE("The miss counts are fields of the specification in every form, in their table's range",
          "[stroke_assistance]") {
  const TrialSpec spec = always_missing({"--assist-after-misses", "2", "--hint-after-misses", "1"});
  // The command line's words and JSON give it back.
  CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
  CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
  const nlohmann::json json = nlohmann::json::parse(trial_spec_json(spec));
  CHECK(json.at("assist_after_misses") == 2.0);
  CHECK(json.at("hint_after_misses") == 1.0);
  // Every field of StrokeAcceptance's table is one of the specification, of the same key and range.
  for (const ParameterField<StrokeAcceptance>& entry : ParameterTable<StrokeAcceptance>::fields()) {
    const SchemaField* field = SchemaOf<TrialSpec>::get().field(entry.name);
    REQUIRE(field != nullptr);
    if (field->kind == FieldKind::integer) {  // a miss count: the whole numbers of the table's range
      CHECK(entry.name.ends_with("_misses"));
      CHECK(static_cast<double>(field->integer_low) == entry.range.low);
      CHECK(static_cast<double>(field->integer_high) == entry.range.high);
    } else {
      CHECK(field->range.low == entry.range.low);
      CHECK(field->range.high == entry.range.high);
    }
    CHECK(field->option.starts_with("--"));
    CHECK(json.contains(std::string(entry.name)));
  }
  // A JSON specification a person writes: a key left out keeps its default.
  const TrialSpec from_file =
      *trial_spec_from_json(R"({"characters": "人", "assist_after_misses": 1})", "s.json");
  CHECK(from_file.acceptance.assist_after_misses == 1.0);
  CHECK(from_file.acceptance.hint_after_misses == StrokeAcceptance{}.hint_after_misses);
  // Out of range, or not a whole number (the counts are integers): refused naming the field in both its
  // forms.
  CHECK_THROWS_WITH(trial_spec_from_args(std::vector<std::string>{"人", "--assist-after-misses", "1001"}),
                    Catch::Contains("assist_after_misses (--assist-after-misses)"));
  CHECK_THROWS_WITH(
      trial_spec_from_args(std::vector<std::string>{"人", "--hint-after-misses", "2.5"}),
      Catch::Contains("hint_after_misses (--hint-after-misses)") && Catch::Contains("not an integer"));
  CHECK_THROWS_WITH(trial_spec_from_json(R"({"characters": "人", "hint_after_misses": -1})", "s.json"),
                    Catch::Contains("s.json") && Catch::Contains("/hint_after_misses"));
}

TEST_CASE(
    "A record holds the miss counts the trial ran with and replays with them, and an earlier record's "
    "specification states the acceptance it ran with",
    "[stroke_assistance]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  const TrialSpec spec = always_missing({"--assist-after-misses", "2", "--hint-after-misses", "1"});
  SimulatedWriting writing(spec);
  const TrialRun first =
      run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
  const std::string json = recorded_trial_json(recorded_trial(spec, first, writing, scene));
  const nlohmann::json document = nlohmann::json::parse(json);
  CHECK(document.at("trial").at("assist_after_misses") == 2.0);
  CHECK(document.at("trial").at("hint_after_misses") == 1.0);
  const RecordedTrial recorded = read_recorded_trial(json, "r.json");
  CHECK(recorded.spec.acceptance == spec.acceptance);
  CHECK(recorded.force_law.acceptance == spec.acceptance);
  CHECK(recorded.defaulted.empty());
  SimulatedWriting again_writing = recorded_writing(recorded);
  const TrialRun again = rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), scene,
                                     study_test::trial_inputs(&again_writing));
  CHECK(again.options.force.acceptance.assist_after_misses == 2.0);
  REQUIRE(again.result.metrics.per_stroke.size() == first.result.metrics.per_stroke.size());
  for (std::size_t i = 0; i < first.result.metrics.per_stroke.size(); ++i) {
    CHECK(again.result.metrics.per_stroke[i].attempts == first.result.metrics.per_stroke[i].attempts);
    CHECK(again.result.metrics.per_stroke[i].attempts <= 2);  // the second's misses may be off its start
    CHECK(again.result.metrics.per_stroke[i].assisted);
  }
  CHECK(again.result.metrics.per_stroke[0].attempts == 2);
  CHECK(again.result.trace.size() == first.result.trace.size());

  // A caller's force law (a study condition's quiz) replaces the acceptance stated: the record's
  // specification states the one that ran.
  StrokeAcceptance given = StrokeAcceptance{};
  given.assist_after_misses = 3;
  TrialOptions ran = first.options;
  ran.force.acceptance = given;
  CHECK(recorded_trial(TrialSpec{spec}, ran, &writing.profile(), scene).spec.acceptance == given);

  // A version-5 record, written before the specification stated the acceptance: its specification takes
  // the acceptance its force law ran with, and no field of it is said to take its default.
  nlohmann::json v5 = document;
  v5["version"] = 5;
  for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields())
    v5["trial"].erase(std::string(field.name));
  const RecordedTrial earlier = read_recorded_trial(v5.dump(), "v5.json");
  StrokeAcceptance as_v5 = recorded.force_law.acceptance;
  as_v5.use_version_6_coverage();  // records before version 7 ran without the centred rule
  as_v5.use_version_7_misses();    // and before version 8 counted a miss at a lift in WS only
  CHECK(earlier.spec.acceptance == as_v5);
  CHECK(earlier.force_law.acceptance == as_v5);
  CHECK(earlier.spec.acceptance.assist_after_misses == 2.0);
  CHECK(earlier.defaulted.empty());

  // A version-6 record, written before the centred rule: it runs without it, in its specification and its
  // force law alike, and the rule's other fields take their defaults (inert with the rule off).
  nlohmann::json v6 = document;
  v6["version"] = 6;
  for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields()) {
    if (!std::string_view(field.name).starts_with("centred_") && field.name != "miss_min_path_m") continue;
    v6["trial"].erase(std::string(field.name));
    v6["force_law"]["acceptance"].erase(std::string(field.name));
  }
  const RecordedTrial sixth = read_recorded_trial(v6.dump(), "v6.json");
  CHECK(sixth.spec.acceptance == as_v5);
  CHECK(sixth.force_law.acceptance == as_v5);
  CHECK(sixth.defaulted.size() == 6);  // balance, shortest and longest, in the trial and the force law
  for (const std::string& pointer : sixth.defaulted)
    CHECK(pointer.find("centred_coverage") == std::string::npos);

  // A version-7 record, written before a pen-down off the stroke's start was a miss: it counts a lift in WS
  // only (miss_min_path_m 0), the value the version's rule fixes, never said to be its default.
  nlohmann::json v7 = document;
  v7["version"] = 7;
  v7["trial"].erase("miss_min_path_m");
  v7["force_law"]["acceptance"].erase("miss_min_path_m");
  const RecordedTrial seventh = read_recorded_trial(v7.dump(), "v7.json");
  StrokeAcceptance as_v7 = recorded.force_law.acceptance;
  as_v7.use_version_7_misses();
  CHECK(seventh.spec.acceptance == as_v7);
  CHECK(seventh.force_law.acceptance == as_v7);
  CHECK(seventh.force_law.acceptance.centred_coverage_fraction ==
        StrokeAcceptance{}.centred_coverage_fraction);
  CHECK(seventh.defaulted.empty());
  CHECK(seventh.version_rules.size() == 2);  // the field in the trial and in the force law, each taking 0
  CHECK(recorded.force_law.acceptance.miss_min_path_m == StrokeAcceptance{}.miss_min_path_m);
}
