// The one trial specification: both forms (JSON, command-line words) round-trip, errors name the field,
// and its runner writes a trial with the simulated writer as an input.
#include "calligraphy/trial/trial_spec.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/whole_trial.hpp"
#include "study_test_devices.hpp"

using namespace calligraphy;

namespace {

// A specification with every field away from its default.
TrialSpec everything_set() {
  TrialSpec spec;
  spec.characters = "口九";
  spec.device = "emulated-phantom";
  spec.guidance = true;
  spec.guidance_mode = GuidanceMode::fading;
  spec.guidance_gain = 0.3;
  spec.writer = TrialWriter::simulated;
  spec.writer_profile = "skilled";
  spec.writer_parameters = {{"bias_offset_m", 0.0005}, {"stroke_jitter_m", 0.0}};
  spec.seed = 18446744073709551615ULL;
  spec.rate_hz = 2000.0 / 3.0;  // no short decimal: the text must keep every bit
  spec.pacing = TrialPacing::real_time;
  spec.realtime = RealtimeMode::enforce;
  spec.watchdog_s = 0.2;
  spec.max_duration_s = 12.5;
  spec.json_file = "out.json";
  spec.csv_file = "-";
  spec.svg_file = "out.svg";
  spec.record_file = "teacher.json";
  return spec;
}

// A valid specification drawn at random (guidance, mode, pacing, numbers and outputs).
TrialSpec random_spec(std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  TrialSpec spec;
  spec.characters = random() % 2 ? "永" : "十人";
  spec.guidance = random() % 4 != 0;
  if (spec.guidance && random() % 2) {
    switch (random() % 4) {
      case 0:
        spec.guidance_mode = GuidanceMode::fading;
        spec.guidance_gain = unit(random);
        break;
      case 1:
        spec.guidance_mode = GuidanceMode::assist_as_needed;
        spec.assist_band_m = unit(random) * 0.004;
        break;
      case 2:
        spec.guidance_mode = GuidanceMode::error_amplification;
        spec.amplification_gain = unit(random);
        break;
      default:
        spec.guidance_mode = GuidanceMode::timing;
        spec.timing_speed_m_s = 0.001 + unit(random) * 0.1;
        break;
    }
  }
  spec.writer = static_cast<TrialWriter>(random() % 3);
  if (spec.writer != TrialWriter::person && random() % 2) {
    spec.writer_profile = "foreign";
    spec.writer_parameters.push_back({"stroke_jitter_m", unit(random) * 1e-4});  // every bit must survive
  }
  spec.seed = random();
  spec.pacing = static_cast<TrialPacing>(random() % 3);
  spec.rate_hz = 100.0 + unit(random) * 9900.0;
  spec.max_duration_s = 1.0 + unit(random) * 100.0;
  if (spec.pacing != TrialPacing::lock_step) spec.watchdog_s = static_cast<double>(random() % 60001) / 1000.0;
  if (random() % 2) spec.json_file = "m" + std::to_string(random() % 10) + ".json";
  if (random() % 2) spec.csv_file = "-";
  return spec;
}

std::string spec_error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("a trial specification round-trips through its JSON and its command-line words") {
  SECTION("defaults") {
    TrialSpec spec;
    spec.characters = "永";
    CHECK(trial_spec_args(spec) == std::vector<std::string>{"永"});
    CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
    CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
  }
  SECTION("every field set") {
    const TrialSpec spec = everything_set();
    spec.validate();
    CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
    CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
    // and the two forms meet: JSON -> spec -> words -> spec
    CHECK(*trial_spec_from_args(trial_spec_args(*trial_spec_from_json(trial_spec_json(spec), "x"))) == spec);
  }
  SECTION("subnormal values are finite numbers like any other") {
    TrialSpec spec;
    spec.characters = "永";
    spec.guidance_mode = GuidanceMode::assist_as_needed;
    spec.assist_band_m = 1e-310;
    REQUIRE_NOTHROW(spec.validate());
    CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
    CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
    spec.guidance_mode = GuidanceMode::fading;
    spec.assist_band_m = TrialSpec{}.assist_band_m;
    spec.guidance_gain = std::numeric_limits<double>::denorm_min();
    REQUIRE_NOTHROW(spec.validate());
    CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
    CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
  }
  SECTION("200 random specifications") {
    std::mt19937_64 random(20261123);
    for (int i = 0; i < 200; ++i) {
      const TrialSpec spec = random_spec(random);
      INFO(trial_spec_json(spec));
      REQUIRE_NOTHROW(spec.validate());
      CHECK(*trial_spec_from_args(trial_spec_args(spec)) == spec);
      CHECK(*trial_spec_from_json(trial_spec_json(spec), "spec.json") == spec);
    }
  }
}

TEST_CASE("the writer's settings are numbers in the JSON, and a record's older \"key=value\" text is read") {
  TrialSpec spec;
  spec.characters = "十";
  spec.writer_parameters = {{"bias_offset_m", 0.01 / 3.0}, {"stroke_jitter_m", 1.0 / 3.0 * 1e-4}};
  const std::string text = trial_spec_json(spec);
  CHECK_THAT(text, Catch::Contains("\"key\": \"bias_offset_m\"") && !Catch::Contains("bias_offset_m="));
  CHECK(*trial_spec_from_json(text, "spec.json") == spec);
  const TrialSpec older = *trial_spec_from_json(
      R"({"characters": "十", "writer_parameters": ["bias_offset_m=0.004", "stroke_jitter_m=1e-5"]})",
      "old.json");
  CHECK(older.writer_parameters ==
        std::vector<WriterSetting>{{"bias_offset_m", 0.004}, {"stroke_jitter_m", 1e-5}});
  CHECK_THAT(spec_error_of([] {
               (void)*trial_spec_from_json(
                   R"({"characters": "十", "writer_parameters": [{"key": "bias_offset_m"}]})", "s.json");
             }),
             Catch::Contains("s.json: /writer_parameters/0") && Catch::Contains("value"));
  CHECK_THAT(spec_error_of([] {
               (void)*trial_spec_from_json(R"({"characters": "十", "writer_parameters": ["bias_offset_m"]})",
                                           "s.json");
             }),
             Catch::Contains("s.json: /writer_parameters/0") && Catch::Contains("key=value"));
}

TEST_CASE("every field of the specification has both names and a parser") {
  TrialSpec spec = everything_set();
  for (const TrialSpecField& field : trial_spec_fields()) {
    INFO(field.key);
    CHECK(!field.help.empty());
    // Setting a field from its own text, by either name, gives the same specification back.
    for (const std::string_view name : {field.key, field.option}) {
      TrialSpec copy = spec;
      if (field.repeated) copy.writer_parameters.clear();
      for (const std::string& text : trial_spec_field_text(spec, field.key))
        set_trial_spec_field(copy, name, text);
      CHECK(copy == spec);
    }
  }
}

TEST_CASE("a specification's errors name the field in both its forms") {
  TrialSpec spec;
  spec.characters = "永";
  const auto fails_naming = [](TrialSpec bad, const std::string& expected) {
    const std::string message = spec_error_of([&] { bad.validate(); });
    INFO(message);
    CHECK(message.find(expected) != std::string::npos);
  };
  TrialSpec bad = spec;
  bad.characters = "";
  fails_naming(bad, "characters (CHARS)");
  bad = spec;
  bad.guidance = false;
  bad.guidance_mode = GuidanceMode::fading;
  fails_naming(bad, "guidance_mode (--guidance-mode)");
  bad = spec;
  bad.guidance_gain = 0.5;
  fails_naming(bad, "guidance_gain (--guidance-gain): applies to guidance mode 'fading' only");
  bad = TrialSpec{};
  bad.characters = "永";
  bad.assist_band_m = 0.002;
  fails_naming(bad, "assist_band_m (--assist-band): applies to guidance mode 'assist-as-needed' only");
  bad.guidance_mode = GuidanceMode::assist_as_needed;
  bad.assist_band_m = -0.001;
  fails_naming(bad, "assist_band_m (--assist-band)");
  bad = TrialSpec{};
  bad.characters = "永";
  bad.guidance_mode = GuidanceMode::error_amplification;
  bad.amplification_gain = 1.5;
  fails_naming(bad, "amplification_gain (--amplification-gain)");
  bad = TrialSpec{};
  bad.characters = "永";
  bad.timing_speed_m_s = 0.05;
  fails_naming(bad, "timing_speed_m_s (--timing-speed): applies to guidance mode 'timing' only");
  bad = spec;
  bad.guidance_mode = GuidanceMode::replay;
  fails_naming(bad, "teacher (--teacher): required");
  // A teacher given as samples to the runner needs no file, and a file beside them would not be read.
  CHECK_NOTHROW(bad.validate(TeacherSource::samples));
  bad.teacher = "teacher.json";
  CHECK_NOTHROW(bad.validate());
  CHECK_THROWS_WITH(bad.validate(TeacherSource::samples),
                    Catch::Contains("teacher (--teacher): the teacher is given as samples"));
  bad = spec;
  bad.writer = TrialWriter::person;
  bad.writer_profile = "skilled";
  fails_naming(bad, "writer_profile (--writer-profile)");
  bad = spec;
  bad.writer_profile = "";
  fails_naming(bad, "writer_profile (--writer-profile): no profile named");
  // The profile is one of the known ones, refused where the specification is checked (so a record naming
  // another is refused as the option is); its settings are the simulated writer's to check, naming the same
  // fields.
  bad = spec;
  bad.writer_profile = "expert";
  fails_naming(bad, "writer_profile (--writer-profile): unknown writer profile 'expert'");
  CHECK_THAT(spec_error_of([&] { (void)writer_profile_of(bad); }),
             Catch::Contains("writer_profile (--writer-profile)") && Catch::Contains("expert"));
  CHECK_THAT(spec_error_of([&] { SimulatedWriting refused(bad); }),
             Catch::Contains("writer_profile (--writer-profile)"));
  bad = spec;
  bad.writer_parameters = {{"no_such_key", 1.0}};
  CHECK_THAT(spec_error_of([&] { (void)writer_profile_of(bad); }),
             Catch::Contains("writer_parameters (--writer-param): 'no_such_key=1'") &&
                 Catch::Contains("known: hand_stiffness_n_per_m"));
  bad.writer_parameters = {{"bias_offset_m", -1.0}};
  CHECK_THAT(spec_error_of([&] { (void)writer_profile_of(bad); }),
             Catch::Contains("writer_parameters (--writer-param): 'bias_offset_m=-1'"));
  bad = spec;
  bad.pacing = TrialPacing::real_time;
  bad.rate_hz = 20000.0;
  fails_naming(bad, "rate_hz (--rate)");
  bad = spec;
  bad.max_duration_s = 1e6;
  fails_naming(bad, "max_duration_s (--max-duration)");
  bad = spec;
  bad.record_file = "-";
  fails_naming(bad, "record_file (--record)");

  CHECK_THAT(
      spec_error_of([] {
        (void)*trial_spec_from_args(std::vector<std::string>{"永", "--pacing", "lock_step"});
      }),
      Catch::Contains("pacing (--pacing): 'lock_step' is not one of 'auto', 'lock-step', 'real-time'"));
  CHECK_THAT(spec_error_of([] {
               (void)*trial_spec_from_args(std::vector<std::string>{"永", "--guidence", "on"});
             }),
             Catch::Contains("no field '--guidence'"));
  CHECK_THAT(spec_error_of([] {
               (void)*trial_spec_from_args(std::vector<std::string>{"永", "--seed"});
             }),
             Catch::Contains("--seed: needs a value"));
  CHECK_THAT(
      spec_error_of([] { (void)*trial_spec_from_json(R"({"characters": "永", "sede": 3})", "s.json"); }),
      Catch::Contains("s.json") && Catch::Contains("sede"));
  CHECK_THAT(
      spec_error_of([] { (void)*trial_spec_from_json(R"({"characters": "永", "seed": -3})", "s.json"); }),
      Catch::Contains("s.json: /seed"));
  CHECK_THAT(spec_error_of(
                 [] { (void)*trial_spec_from_json(R"({"characters": "永", "guidance": "on"})", "s.json"); }),
             Catch::Contains("s.json: /guidance: expected true or false"));
}

TEST_CASE("the runner of a specification gives the simulated writer to the trial as its hand") {
  TrialSpec spec;
  spec.characters = "十";
  spec.seed = 4;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  SimulatedWriting writing(spec);
  const TrialRun run =
      run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs(&writing));
  CHECK(run.simulated_writer);
  REQUIRE(writing.log().has_value());
  CHECK_FALSE(writing.log()->attempts.empty());
  // The writer marked its attempts in the trace (mark_writer_attempts), after the hand let go.
  CHECK(std::any_of(run.result.trace.begin(), run.result.trace.end(),
                    [](const TrialSample& sample) { return sample.attempt > 0; }));
  // Without a hand maker, the runner names what is missing instead of running no writer.
  CHECK_THAT(spec_error_of([&] {
               (void)run_trial_spec(Checked<TrialSpec>::check(spec), scene, study_test::trial_inputs());
             }),
             Catch::Contains("no hand maker") && Catch::Contains("TrialRunInputs::hand_maker"));
  CHECK(run.result.end == TrialEnd::completed);
  CHECK(run.metrics.strokes_total == 2);
  CHECK(run.metrics.strokes_accepted == 2);
  CHECK(run.options.force.guidance);
  // The one metrics record is the trace's, as any front-end scores it.
  CHECK(run.metrics.total_time_s ==
        trial_writing_metrics(scene, run.result, run.options.force.acceptance).total_time_s);

  TrialSpec person = spec;
  person.writer = TrialWriter::person;
  CHECK_THAT(spec_error_of([&] {
               (void)run_trial_spec(Checked<TrialSpec>::check(person), scene, study_test::trial_inputs());
             }),
             Catch::Contains("writer (--writer): 'person'"));
  TrialSpec nowhere = spec;
  nowhere.device = "no-such-device";
  CHECK_THROWS_AS(
      run_trial_spec(Checked<TrialSpec>::check(nowhere), scene, study_test::trial_inputs(&writing)),
      DeviceNotFound);
  // The library makes no registry of its own: the caller passes one, or a device.
  CHECK_THAT(spec_error_of([&] { (void)run_trial_spec(Checked<TrialSpec>::check(spec), scene); }),
             Catch::Contains("no device and no registry to create \"simulated\""));
}

namespace {

// Whether `T` has a member `force_law`, `safety` or `passivity`: a part of the trial given beside it.
template <typename T>
concept gives_trial_parts = requires(const T& t) {
  t.force_law;
}
|| requires(const T& t) { t.safety; }
|| requires(const T& t) { t.passivity; };

}  // namespace

TEST_CASE("the runner runs the whole trial its one builder made, with a force law made before the trial") {
  // The runtime handles carry no part of the trial: nothing beside the checked whole trial replaces one.
  static_assert(!gives_trial_parts<TrialRunInputs>);
  static_assert(gives_trial_parts<WholeTrialParts>);  // the concept sees them where they are
  static_assert(!std::is_constructible_v<Checked<WholeTrial>, WholeTrial>);
  static_assert(
      !std::is_invocable_v<decltype(&run_whole_trial), WholeTrial, const Scene&, const TrialRunInputs&>);
  TrialSpec spec;
  spec.characters = "十";
  spec.seed = 4;
  spec.max_duration_s = 0.05;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  SimulatedWriting writing(spec);
  TrialRunInputs inputs = study_test::trial_inputs(&writing);
  ForceLawParameters force;
  force.guidance_stiffness_n_per_m = 250.0;
  force.acceptance.hint_after_misses = 2.0;
  inputs.lock_memory = false;
  const auto checked = Checked<TrialSpec>::check(spec);
  const Checked<WholeTrial> whole = build_whole_trial(checked, DeviceInfo{}, {.force_law = force});
  // The given force law's acceptance is the trial's: the specification states it.
  CHECK(whole->spec.acceptance == force.acceptance);
  CHECK_FALSE(spec.acceptance == force.acceptance);
  const TrialRun run = run_whole_trial(whole, scene, inputs);
  CHECK(run.options.force.guidance_stiffness_n_per_m == 250.0);
  CHECK(run.options.force.acceptance == force.acceptance);
  CHECK_FALSE(run.options.loop.lock_memory);
  force.guidance_law = FadingGuidance{.gain = 0.5};
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, DeviceInfo{}, {.force_law = force}); }),
             Catch::Contains("force_law: its guidance (fading) is not the specification's (fixed)"));
}

TEST_CASE("the one builder refuses a part out of range naming the part, before any device exists") {
  TrialSpec spec;
  spec.characters = "十";
  spec.writer = TrialWriter::person;
  spec.device = "emulated-phantom";
  const auto checked = Checked<TrialSpec>::check(spec);
  const DeviceInfo figures;  // the builder is given figures only: it can open no device
  ForceLawParameters force;
  force.guidance_stiffness_n_per_m = -1.0;
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, figures, {.force_law = force}); }),
             Catch::StartsWith("force_law: "));
  SafetyChainParameters safety;
  safety.max_force_change_n_per_tick = -0.5;
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, figures, {.safety = safety}); }),
             Catch::StartsWith("safety: "));
  // A low-pass at or above the loop's Nyquist frequency (500 Hz at 1 kHz) filters nothing it samples.
  SafetyChainParameters aliased;
  aliased.low_pass_cutoff_hz = 0.5 * spec.rate_hz;
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, figures, {.safety = aliased}); }),
             Catch::StartsWith("safety: low_pass_cutoff_hz") && Catch::Contains("half the servo rate"));
  aliased.low_pass_cutoff_hz = 0.49 * spec.rate_hz;
  CHECK_NOTHROW(build_whole_trial(checked, figures, {.safety = aliased}));
  PassivityParameters passivity;
  passivity.enabled = true;
  passivity.max_damping_n_s_per_m = -2.0;
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, figures, {.passivity = passivity}); }),
             Catch::StartsWith("passivity: "));
  CHECK_THAT(spec_error_of([&] { (void)build_whole_trial(checked, figures, {.writer = WriterProfile{}}); }),
             Catch::StartsWith("writer: ") && Catch::Contains("a person writes"));
  CHECK_THAT(spec_error_of([&] {
               (void)build_whole_trial(checked, figures, {.simulated_device = SimulatedDeviceParameters{}});
             }),
             Catch::StartsWith("simulated_device: ") && Catch::Contains("emulated-phantom"));
  // The same parts in range make a whole trial; the stated force law's default stiffnesses are fitted to
  // the figures given (the Phantom Omni's 700 N/m against the paper's 800 N/m).
  DeviceInfo omni;
  omni.max_stiffness_n_per_m = 700.0;
  const Checked<WholeTrial> whole = build_whole_trial(checked, omni, {.safety = SafetyChainParameters{}});
  CHECK(whole->force_law.paper_stiffness_n_per_m == 700.0);
  CHECK(whole->force_law.paper_stiffness_n_per_m < ForceLawParameters{}.paper_stiffness_n_per_m);
}

namespace {

// One of a range's ends or a value inside it, drawn at random: the derivation must hold at the bounds too.
double bound_or_inside(std::mt19937_64& random, const ParameterRange& range, double inside) {
  switch (random() % 3) {
    case 0:
      return range.low_open ? std::nextafter(range.low, range.high) : range.low;
    case 1:
      return std::isfinite(range.high)
                 ? (range.high_open ? std::nextafter(range.high, range.low) : range.high)
                 : inside;
    default:
      return inside;
  }
}

// A valid specification with its numbers often at their bounds.
TrialSpec spec_at_bounds(std::mt19937_64& random) {
  TrialSpec spec = random_spec(random);
  switch (spec.guidance_mode) {
    case GuidanceMode::fading:
      spec.guidance_gain =
          bound_or_inside(random, parameter_field(&FadingGuidance::gain).range, spec.guidance_gain);
      break;
    case GuidanceMode::assist_as_needed:
      spec.assist_band_m =
          bound_or_inside(random, parameter_field(&AssistAsNeededGuidance::band_m).range, spec.assist_band_m);
      break;
    case GuidanceMode::error_amplification:
      spec.amplification_gain = bound_or_inside(
          random, parameter_field(&ErrorAmplificationGuidance::gain).range, spec.amplification_gain);
      break;
    case GuidanceMode::timing:
      spec.timing_speed_m_s =
          bound_or_inside(random, parameter_field(&TimingGuidance::speed_m_s).range, spec.timing_speed_m_s);
      break;
    default:
      break;
  }
  const bool real_time = spec.pacing == TrialPacing::real_time;
  if (random() % 3 == 0) spec.rate_hz = random() % 2 ? 100.0 : (real_time ? 10000.0 : 100000.0);
  if (random() % 3 == 0) spec.max_duration_s = std::min(86400.0, std::nextafter(1e7 / spec.rate_hz, 0.0));
  if (spec.pacing != TrialPacing::lock_step && random() % 3 == 0) spec.watchdog_s = random() % 2 ? 0.0 : 60.0;
  return spec;
}

}  // namespace

TEST_CASE("the options a checked specification states are valid on any device, unchecked again") {
  // trial_options derives them from the checked specification without a second check (checked.hpp): this is
  // the promise that lets it, on specifications at their bounds and devices of every stiffness limit.
  std::mt19937_64 random(20261126);
  const double limits[] = {0.0, 1e-9, 1.0, 300.0, 700.0, 1e9, std::numeric_limits<double>::quiet_NaN()};
  for (int i = 0; i < 500; ++i) {
    const TrialSpec spec = spec_at_bounds(random);
    INFO(trial_spec_json(spec));
    const auto checked = Checked<TrialSpec>::check(spec);
    DeviceInfo device;
    device.max_stiffness_n_per_m = limits[random() % std::size(limits)];
    const TrialOptions options = trial_options(checked, device);
    REQUIRE_NOTHROW(options.validate());
    CHECK(options.rate_hz == spec.rate_hz);
    CHECK(options.max_duration_s == spec.max_duration_s);
    CHECK(options.force.guidance == spec.guidance);
  }
}

TEST_CASE("a specification reaches the runner checked: it takes no unchecked one") {
  static_assert(!std::is_constructible_v<Checked<TrialSpec>, TrialSpec>);
  static_assert(!std::is_convertible_v<TrialSpec, Checked<TrialSpec>>);
  static_assert(
      !std::is_invocable_v<decltype(&run_trial_spec), TrialSpec, const Scene&, const TrialRunInputs&>);
  static_assert(std::is_invocable_v<decltype(&run_trial_spec), Checked<TrialSpec>, const Scene&,
                                    const TrialRunInputs&>);
  TrialSpec spec;
  spec.characters = "十";
  spec.guidance_mode = GuidanceMode::fading;
  spec.guidance_gain = 1.5;
  CHECK_THAT(spec_error_of([&] { (void)Checked<TrialSpec>::check(spec); }), Catch::Contains("guidance_gain"));
  // A checked replay runs on one teacher: its file or the caller's samples, named when neither is there.
  spec.guidance_gain = 1.0;
  spec.guidance_mode = GuidanceMode::replay;
  const auto replay = Checked<TrialSpec>::check(spec, TeacherSource::samples);
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  CHECK_THAT(spec_error_of([&] { (void)run_trial_spec(replay, scene, study_test::trial_inputs()); }),
             Catch::Contains("teacher (--teacher): a replay runs on the teacher's samples"));
}
