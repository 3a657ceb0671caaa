// The record is the specification (recorded_trial.hpp): random valid specifications, every part away from
// its defaults, survive JSON both ways with every double's bits; a trial run again from its record's JSON
// gives the same trace bit for bit on the simulated device; a record that is not one is refused by name.
#include "calligraphy/trial/recorded_trial.hpp"

#include <bit>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "study_test_devices.hpp"

using namespace calligraphy;

namespace {

// A value drawn inside `range`, with full-precision digits (so that the JSON must keep every bit).
double draw(const ParameterRange& range, std::mt19937_64& random) {
  const double low = range.low;
  const double high = std::isinf(range.high) ? low + 1000.0 : range.high;
  std::uniform_real_distribution<double> uniform(low, high);
  for (;;) {
    const double value = uniform(random);
    if (range.contains(value)) return value;
  }
}

template <typename S>
void randomise(S& object, std::mt19937_64& random) {
  for (const ParameterField<S>& field : ParameterTable<S>::fields())
    object.*field.member = draw(field.range, random);
}

// Every table field of two objects, compared by bit pattern.
template <typename S>
void require_same_bits(const S& a, const S& b) {
  for (const ParameterField<S>& field : ParameterTable<S>::fields()) {
    INFO(ParameterTable<S>::name << "." << field.name);
    CHECK(std::bit_cast<std::uint64_t>(a.*field.member) == std::bit_cast<std::uint64_t>(b.*field.member));
  }
}

RecordedTrial random_recorded_trial(std::mt19937_64& random, GuidanceMode mode) {
  RecordedTrial r;
  r.spec.characters = "永";
  r.spec.guidance_mode = mode;
  r.spec.seed = random();
  r.spec.rate_hz = 100.0 + std::uniform_real_distribution<double>(0.0, 4900.0)(random);
  r.spec.max_duration_s = 1.0 + std::uniform_real_distribution<double>(0.0, 100.0)(random);
  r.spec.writer_profile = "foreign";
  r.spec.writer_parameters = {{"hesitation_s", 0.25}};
  if (mode == GuidanceMode::replay) {
    r.spec.teacher = "teacher.json";
    r.teacher_sha256 = std::string(64, 'b');  // the file it read, as a replay's writer states it
  }
  randomise(r.force_law, random);
  r.force_law.constraint_taper_m = r.force_law.constraint_radius_m * 0.5;  // a cross-field rule
  r.force_law.guidance_law = default_guidance_law(mode);
  std::visit(
      [&](auto& law) {
        randomise(law, random);
        using Law = std::decay_t<decltype(law)>;
        if constexpr (requires { law.max_lead_m; }) {  // at most R_res: a cross-struct rule
          law.max_lead_m =
              0.5 * std::min(r.force_law.constraint_radius_m, parameter_field(&Law::max_lead_m).range.high);
        }
      },
      r.force_law.guidance_law);
  // A record states its mode's value in the specification and in the force law, the same.
  if (auto* fading = std::get_if<FadingGuidance>(&r.force_law.guidance_law))
    r.spec.guidance_gain = fading->gain;
  if (auto* band = std::get_if<AssistAsNeededGuidance>(&r.force_law.guidance_law))
    r.spec.assist_band_m = band->band_m;
  if (auto* amplified = std::get_if<ErrorAmplificationGuidance>(&r.force_law.guidance_law))
    r.spec.amplification_gain = amplified->gain;
  if (auto* timing = std::get_if<TimingGuidance>(&r.force_law.guidance_law))
    r.spec.timing_speed_m_s = timing->speed_m_s;
  r.force_law.acceptance.corridor_m = 0.0071234567890123;
  r.force_law.acceptance.shortfall_fraction = 0.41;
  r.spec.acceptance = r.force_law.acceptance;  // a record states the acceptance its force law ran with
  r.force_law.nearest.method = NearestPointMethod::newton;
  r.force_law.nearest.newton_starts = 5;
  randomise(r.safety, random);
  r.safety.max_continuous_force_n = r.safety.max_force_n * 0.5;
  r.passivity.enabled = true;
  randomise(r.passivity, random);
  WriterProfile writer = WriterProfile::foreign();
  writer.bias_offset_m = 0.0031234567890123;
  writer.max_attempts_per_stroke = 3;
  r.writer = writer;
  r.layout.centre_m = {0.001, -0.002};
  r.scene_sha256 = std::string(64, 'a');
  r.library_version = "test";
  return r;
}

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("A recorded trial survives JSON both ways, every double to the bit", "[recorded_trial]") {
  std::mt19937_64 random(20261125);
  for (int round = 0; round < 50; ++round) {
    for (GuidanceMode mode : guidance_modes()) {
      const RecordedTrial r = random_recorded_trial(random, mode);
      const std::string text = recorded_trial_json(r);
      INFO(text);
      const RecordedTrial back = read_recorded_trial(text, "spec.json");
      CHECK(back.spec == r.spec);
      require_same_bits(back.force_law, r.force_law);
      CHECK(back.force_law.guidance_law.index() == r.force_law.guidance_law.index());
      CHECK(back.force_law.acceptance.corridor_m == r.force_law.acceptance.corridor_m);
      CHECK(back.force_law.nearest.method == NearestPointMethod::newton);
      CHECK(back.force_law.nearest.newton_starts == 5);
      require_same_bits(back.safety, r.safety);
      require_same_bits(back.passivity, r.passivity);
      CHECK(back.passivity.enabled);
      REQUIRE(back.writer.has_value());
      for (const std::string& key : writer_parameter_names())
        CHECK(writer_parameter(*back.writer, key) == writer_parameter(*r.writer, key));
      CHECK(back.layout.centre_m == r.layout.centre_m);
      // Written again, the same text: nothing is lost or reordered.
      CHECK(recorded_trial_json(back) == text);
    }
  }
}

TEST_CASE("A trial run again from its record gives the same trace, bit for bit", "[recorded_trial]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  TrialSpec spec;
  spec.characters = "十";
  spec.guidance_mode = GuidanceMode::assist_as_needed;
  spec.assist_band_m = 0.0007;
  spec.writer_profile = "novice";
  spec.writer_parameters = {{"bias_offset_m", 0.003}, {"stroke_jitter_m", 0.0013}};
  spec.seed = 99;
  spec.rate_hz = 800.0;
  spec.max_duration_s = 30.0;
  SimulatedWriting writing(spec);
  TrialRunInputs inputs = study_test::trial_inputs(&writing);
  ForceLawParameters force;
  force.guidance_law = AssistAsNeededGuidance{.band_m = 0.0007};
  force.off_stroke_force_n = 0.35;  // parts a specification alone does not state
  force.friction_coefficient = 0.21;
  force.guidance_stiffness_n_per_m = 333.0;
  SafetyChainParameters safety;
  safety.max_force_change_n_per_tick = 0.125;
  const TrialRun first = run_whole_trial(build_whole_trial(Checked<TrialSpec>::check(spec), DeviceInfo{},
                                                           {.force_law = force, .safety = safety}),
                                         scene, inputs);
  REQUIRE(first.result.trace.size() > 100);

  const RecordedTrial recorded =
      read_recorded_trial(recorded_trial_json(recorded_trial(spec, first, writing, scene)), "r.json");
  SimulatedWriting again_writing = recorded_writing(recorded);  // the writer as the record states it
  const TrialRun again = rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), scene,
                                     study_test::trial_inputs(&again_writing));
  REQUIRE(again.result.trace.size() == first.result.trace.size());
  std::size_t different = 0;
  for (std::size_t i = 0; i < first.result.trace.size(); ++i) {
    const TrialSample& a = first.result.trace[i];
    const TrialSample& b = again.result.trace[i];
    different += (a.time_s != b.time_s || a.position_m != b.position_m || a.force_n != b.force_n) ? 1 : 0;
  }
  CHECK(different == 0);

  // The simulated writer wrote it: without its hand maker (sim's recorded_writing) the re-run is refused,
  // naming what to give, rather than run with another hand.
  CHECK_THROWS_WITH(
      (void)rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), scene,
                        study_test::trial_inputs()),
      Catch::Contains("recorded_writing(recorded)") && Catch::Contains("TrialRunInputs::hand_maker"));

  // Without the record's force law, the same specification renders another force: the record carried it.
  const TrialRun plain =
      run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
  bool same = plain.result.trace.size() == first.result.trace.size();
  for (std::size_t i = 0; same && i < first.result.trace.size(); ++i)
    same = plain.result.trace[i].force_n == first.result.trace[i].force_n;
  CHECK_FALSE(same);
}

TEST_CASE("A caller's simulated device states its figures, and the re-run runs on them", "[recorded_trial]") {
  // Its peak force bounds the trial's (the safety chain's 0 is the device's): a record that left it out would
  // re-run on the default device's figures, another trial.
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  TrialSpec spec;
  spec.characters = "十";
  spec.max_duration_s = 20.0;
  SimulatedDeviceParameters weak;
  weak.info.model = "weak";
  weak.info.max_force_n = 0.5;
  weak.info.max_continuous_force_n = 0.4;
  SimulatedWriting writing(spec);
  const TrialRun first = run_whole_trial(
      build_whole_trial(Checked<TrialSpec>::check(spec), weak.info, {.simulated_device = weak}), scene,
      study_test::trial_inputs(&writing));
  REQUIRE(first.result.trace.size() > 100);
  CHECK(first.result.metrics.max_force_n == Approx(0.5));  // the default device's 7.9 N would give more
  RecordedTrial made = recorded_trial(spec, first, writing, scene);
  made.simulated_device = weak;
  const std::string text = recorded_trial_json(made);
  const nlohmann::json info = nlohmann::json::parse(text)["simulated_device"]["info"];
  CHECK(info["model"] == "weak");
  CHECK(info["max_force_n"] == 0.5);
  CHECK(info["max_continuous_force_n"] == 0.4);

  const RecordedTrial recorded = read_recorded_trial(text, "r.json");
  REQUIRE(recorded.simulated_device.has_value());
  CHECK(recorded.simulated_device->info.max_force_n == 0.5);
  SimulatedWriting again_writing = recorded_writing(recorded);
  const TrialRun again = rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), scene,
                                     study_test::trial_inputs(&again_writing));
  REQUIRE(again.result.trace.size() == first.result.trace.size());
  for (std::size_t i = 0; i < first.result.trace.size(); ++i) {
    INFO(i);
    REQUIRE(again.result.trace[i].force_n == first.result.trace[i].force_n);
  }

  // A record of version 8 states no figures: its device reports the simulated Phantom Desktop's.
  nlohmann::json older = nlohmann::json::parse(text);
  older["version"] = 8;
  older["simulated_device"].erase("info");
  const RecordedTrial eighth = read_recorded_trial(older.dump(), "r8.json");
  CHECK(eighth.simulated_device->info.max_force_n == simulated_phantom_desktop_info().max_force_n);
  CHECK(eighth.simulated_device->info.model == simulated_phantom_desktop_info().model);
  // ... and one of version 9 that leaves them out is refused at their pointer.
  older["version"] = 9;
  CHECK_THAT(error_of([&] { (void)read_recorded_trial(older.dump(), "r9.json"); }),
             Catch::Contains("r9.json: /simulated_device/info") && Catch::Contains("missing"));
}

TEST_CASE("A record with a part out of range is refused by the builder, naming it, before a device is made",
          "[recorded_trial]") {
  TrialSpec spec;
  spec.characters = "十";
  spec.seed = 5;
  spec.max_duration_s = 0.05;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  SimulatedWriting writing(spec);
  const TrialRun ran =
      run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
  RecordedTrial recorded = recorded_trial(spec, ran, writing, scene);
  // A registry whose simulated device counts how often it is made.
  int made = 0;
  DeviceRegistry registry;
  registry.register_device(
      "simulated", SimulatedDevice().info(),
      [&made] {
        ++made;
        return std::make_unique<SimulatedDevice>();
      },
      DeviceCapabilities{.moved_by_simulated_hand = true});
  SimulatedWriting again = recorded_writing(recorded);
  TrialRunInputs inputs;
  inputs.registry = &registry;
  inputs.hand_maker = &again;
  const auto checked = Checked<TrialSpec>::check(recorded.spec);
  recorded.safety.max_force_change_n_per_tick = -1.0;
  CHECK_THROWS_WITH((void)rerun_trial(recorded, checked, scene, inputs), Catch::StartsWith("safety: "));
  recorded.safety = ran.options.safety;
  recorded.force_law.guidance_law = FadingGuidance{.gain = 0.5};
  CHECK_THROWS_WITH((void)rerun_trial(recorded, checked, scene, inputs),
                    Catch::StartsWith("force_law: its guidance (fading) is not the specification's (fixed)"));
  CHECK(made == 0);
  // In range again, the record runs, on the one device made for it.
  recorded.force_law = ran.options.force;
  const TrialRun rerun = rerun_trial(recorded, checked, scene, inputs);
  CHECK(made == 1);
  CHECK(rerun.result.trace.size() == ran.result.trace.size());
}

TEST_CASE("A replay naming its teacher's file states the file's SHA-256, written and read",
          "[recorded_trial]") {
  std::mt19937_64 random(11);
  RecordedTrial replay = random_recorded_trial(random, GuidanceMode::replay);
  const std::string good = recorded_trial_json(replay);
  nlohmann::json document = nlohmann::json::parse(good);
  document["teacher_sha256"] = "";
  // Read: refused at its pointer, from version 4 (which introduced it); older records named none.
  CHECK_THAT(error_of([&] { (void)read_recorded_trial(document.dump(), "r.json"); }),
             Catch::Contains("r.json: /teacher_sha256") && Catch::Contains("teacher.json"));
  document["version"] = 3;
  document.erase("teacher_sha256");
  CHECK_NOTHROW((void)read_recorded_trial(document.dump(), "r.json"));
  // A teacher given as samples names no file: nothing to bind.
  document = nlohmann::json::parse(good);
  document["teacher_sha256"] = "";
  document["trial"]["teacher"] = "";
  CHECK_NOTHROW((void)read_recorded_trial(document.dump(), "r.json"));

  // Written: recorded_trial() takes the SHA-256 of the file the replay read, and refuses to write without it.
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  TrialSpec spec;
  spec.characters = "十";
  spec.guidance_mode = GuidanceMode::replay;
  spec.teacher = "teacher.json";
  TrialOptions ran;
  ran.force.guidance_law = ReplayGuidance{};
  CHECK_THROWS_WITH((void)recorded_trial(spec, ran, nullptr, scene),
                    Catch::Contains("teacher.json") && Catch::Contains("SHA-256"));
  CHECK_THROWS_AS((void)recorded_trial(spec, ran, nullptr, scene, "not a sha"), InvalidArgument);
  const std::string sha(64, 'c');
  CHECK(recorded_trial(spec, ran, nullptr, scene, sha).teacher_sha256 == sha);
  spec.teacher.clear();  // samples
  CHECK(recorded_trial(spec, ran, nullptr, scene).teacher_sha256.empty());
  CHECK_THROWS_AS((void)recorded_trial(spec, ran, nullptr, scene, sha), InvalidArgument);
}

TEST_CASE("A record run on other characters is refused", "[recorded_trial]") {
  const Scene ten = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  const Scene person = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  TrialSpec spec;
  spec.characters = "十";
  spec.max_duration_s = 1.0;
  RecordedTrial recorded = recorded_trial(spec, TrialOptions{}, nullptr, ten);
  CHECK(recorded.scene_sha256 == scene_sha256(ten));
  CHECK(scene_sha256(person) != scene_sha256(ten));
  CHECK_THAT(error_of([&] {
               (void)rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), person,
                                 study_test::trial_inputs());
             }),
             Catch::Contains("not the recorded ones") && Catch::Contains("SHA-256"));
}

TEST_CASE("The characters' SHA-256 covers their medians, and a record of the models alone still matches",
          "[recorded_trial]") {
  const Scene ten = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  Scene models_only = ten;
  for (PlacedStroke& stroke : models_only.characters.front().strokes) stroke.median_m.clear();
  Scene moved_median = ten;
  moved_median.characters.front().strokes.back().median_m.back().x() += 1e-9;
  // Another median, or none, is other character data: progress is measured along it.
  CHECK(scene_sha256(models_only) != scene_sha256(ten));
  CHECK(scene_sha256(moved_median) != scene_sha256(ten));
  CHECK_FALSE(scene_is_recorded_one(models_only, scene_sha256(ten)));
  CHECK_FALSE(scene_is_recorded_one(ten, scene_sha256(models_only)));
  // The models' SHA-256 alone, as records stated it before, matches the same models with medians or without.
  CHECK(scene_models_sha256(models_only) == scene_models_sha256(ten));
  CHECK(scene_is_recorded_one(ten, scene_models_sha256(ten)));
  CHECK(scene_is_recorded_one(models_only, scene_models_sha256(ten)));
  const Scene person = Scene::lay_out({CharacterLibrary::embedded().load(U'人')});
  CHECK_FALSE(scene_is_recorded_one(person, scene_models_sha256(ten)));

  TrialSpec spec;
  spec.characters = "十";
  spec.max_duration_s = 1.0;
  spec.seed = 3;
  SimulatedWriting writing(spec);
  const TrialRun first = run_whole_trial(build_whole_trial(Checked<TrialSpec>::check(spec), DeviceInfo{}, {}),
                                         ten, study_test::trial_inputs(&writing));
  RecordedTrial recorded = recorded_trial(spec, first, writing, ten);
  SimulatedWriting again = recorded_writing(recorded);
  CHECK_THAT(error_of([&] {
               (void)rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), models_only,
                                 study_test::trial_inputs(&again));
             }),
             Catch::Contains("not the recorded ones"));
  recorded.scene_sha256 = scene_models_sha256(ten);  // as a record written before stated it
  SimulatedWriting once_more = recorded_writing(recorded);
  CHECK_NOTHROW(rerun_trial(recorded, Checked<TrialSpec>::check(recorded.spec), models_only,
                            study_test::trial_inputs(&once_more)));
}

TEST_CASE("What is not a recorded trial is refused naming the file and the place", "[recorded_trial]") {
  std::mt19937_64 random(7);
  const std::string good = recorded_trial_json(random_recorded_trial(random, GuidanceMode::fixed));
  const auto edited = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json document = nlohmann::json::parse(good);
    edit(document);
    return document.dump();
  };
  const auto refusal = [](const std::string& text) {
    return error_of([&] { (void)read_recorded_trial(text, "r.json"); });
  };
  CHECK_THAT(refusal(R"({"version": 2, "end_reason": "completed"})"),
             Catch::Contains("r.json") && Catch::Contains("no trial specification"));
  CHECK_THAT(refusal(R"({"specification": null})"), Catch::Contains("r.json: /specification"));
  CHECK_THAT(
      refusal(edited([](auto& d) { d["version"] = kRecordedTrialVersion + 1; })),
      Catch::Contains("/version") && Catch::Contains("version " + std::to_string(kRecordedTrialVersion + 1) +
                                                     " is not one this library reads (1 to " +
                                                     std::to_string(kRecordedTrialVersion) + ")"));
  CHECK_THAT(refusal(edited([](auto& d) { d["version"] = 0; })), Catch::Contains("version 0"));
  // Version 1, written before the writer's settings were typed: its "key=value" strings are read.
  const RecordedTrial older = read_recorded_trial(edited([](auto& d) {
                                                    d["version"] = 1;
                                                    d["trial"]["writer_parameters"] = {"bias_offset_m=0.003"};
                                                  }),
                                                  "r.json");
  REQUIRE(older.spec.writer_parameters.size() == 1);
  CHECK(older.spec.writer_parameters[0] == WriterSetting{"bias_offset_m", 0.003});
  CHECK_THAT(refusal(edited([](auto& d) { d["format"] = "other"; })),
             Catch::Contains("r.json: /") && Catch::Contains("format 'other'"));
  CHECK_THAT(refusal(edited([](auto& d) { d["force_law"].erase("off_stroke_force_n"); })),
             Catch::Contains("/force_law") && Catch::Contains("off_stroke_force_n"));
  CHECK_THAT(refusal(edited([](auto& d) { d["force_law"]["crossfade_s"] = -1.0; })),
             Catch::Contains("/force_law") && Catch::Contains("crossfade_s"));
  CHECK_THAT(refusal(edited([](auto& d) { d["force_law"]["guidance_law"]["mode"] = "fading"; })),
             Catch::Contains("/force_law/guidance_law/gain"));
  CHECK_THAT(refusal(edited([](auto& d) {
               d["force_law"]["guidance_law"] = {{"mode", "fading"}, {"gain", 0.5}};
             })),
             Catch::Contains("not the specification's"));
  CHECK_THAT(refusal(edited([](auto& d) { d["safety"]["start_ramp_n_per_s"] = "fast"; })),
             Catch::Contains("/safety/start_ramp_n_per_s"));
  CHECK_THAT(refusal(edited([](auto& d) { d["writer"]["noise_fraction"] = 3.0; })),
             Catch::Contains("/writer/noise_fraction"));
  CHECK_THAT(refusal(edited([](auto& d) { d["trial"]["rate_hz"] = 5.0; })), Catch::Contains("rate"));
  CHECK_THAT(refusal(edited([](auto& d) { d["passivity"]["surprise"] = 1; })), Catch::Contains("surprise"));
  // A simulated writer's record without its profile would re-run with another writer's.
  CHECK_THAT(refusal(edited([](auto& d) {
               d["trial"]["writer"] = "simulated";
               d["writer"] = nullptr;
             })),
             Catch::Contains("r.json: /writer") && Catch::Contains("simulated"));
  // A safety peak past its table's range: a typing error, not a limit.
  CHECK_THAT(refusal(edited([](auto& d) { d["safety"]["max_force_n"] = 1e308; })),
             Catch::Contains("/safety/max_force_n"));
  // Lengths, times and tolerances have finite bounds: the largest double is a typing error, refused by
  // pointer; the bound itself is taken.
  for (const auto& [part, field, bound] :
       {std::tuple{"scene/layout", "box_margin_m", 0.1}, std::tuple{"scene/layout", "start_radius_m", 0.1},
        std::tuple{"scene/layout", "character_size_m", 1.0}, std::tuple{"scene/layout", "spacing_m", 1.0},
        std::tuple{"force_law/nearest", "tolerance", 1e-3},
        std::tuple{"force_law", "constraint_radius_m", 0.1},
        std::tuple{"force_law", "contact_hysteresis_m", 0.1},
        std::tuple{"force_law", "off_stroke_travel_m", 0.1}, std::tuple{"force_law", "crossfade_s", 10.0},
        std::tuple{"force_law", "paper_fade_s", 10.0},
        std::tuple{"safety", "continuous_time_constant_s", 86400.0}}) {
    const std::string pointer = "/" + std::string(part) + "/" + field;
    const bool radius = std::string_view(field) == "constraint_radius_m";
    INFO(pointer);
    const auto set = [&](double value) {
      return edited([&](nlohmann::json& d) {
        d[nlohmann::json::json_pointer(pointer)] = value;
        if (radius) d["force_law"]["constraint_taper_m"] = 0.0;  // at most R_res
      });
    };
    CHECK_THAT(refusal(set(1e308)), Catch::Contains("r.json: " + pointer));
    CHECK_NOTHROW((void)read_recorded_trial(set(bound), "r.json"));
  }
  // Inside a trial record, the pointers name the record's member.
  const std::string record =
      "{\"version\": 2, \"specification\": " + edited([](auto& d) { d["safety"]["max_force_n"] = -1.0; }) +
      "}";
  CHECK_THAT(refusal(record), Catch::Contains("r.json: /specification/safety"));
}
