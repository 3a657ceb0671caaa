// trial: a whole simulated trial (include/calligraphy/trial/trial.hpp, run_simulated_trial) and its
// result. Every binding of the trial runner is in this file.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arguments.hpp"
#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/report/rerun_check.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "calligraphy/trial/trial.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "character_source.hpp"
#include "log_forwarding.hpp"
#include "model_bindings.hpp"
#include "numpy_arrays.hpp"
#include "report_bindings.hpp"
#include "signal_poll.hpp"
#include "writer_settings.hpp"

namespace calligraphy::python {
namespace {

struct TrialCharactersTag {
  static constexpr auto name = py::detail::const_name("Union[str, Character, Sequence[Character], Scene]");
};
struct SceneTag {
  static constexpr auto name = py::detail::const_name("Scene");
};
struct DataFrameTag {
  static constexpr auto name = py::detail::const_name("pandas.DataFrame");
};
struct TeacherTag {
  static constexpr auto name = py::detail::const_name("Union[TeacherRecording, Sequence[TeacherSample]]");
};

// A trial's trace as numpy arrays (one row per servo tick), its metrics and the scene it was written on.
struct PyTrialResult {
  py::array_t<double> time_s, position_m, force_n;
  py::array_t<std::uint8_t> state;
  py::array_t<std::int64_t> stroke, element;
  py::array_t<std::int64_t> attempt;    // 1-based attempt at the stroke, 0 outside any
  py::array_t<std::uint8_t> rewritten;  // 1: part of an attempt written again later
  py::array_t<std::int64_t> stroke_trace_range;
  py::dict metrics;
  py::object scene;
  WriterProfile writer;                 // the profile the simulated writer wrote with
  std::optional<WriterLog> writer_log;  // what it did; empty on a device a person moves
};

PyTrialResult to_python(const TrialResult& result, py::dict metrics, py::object scene) {
  const auto n = static_cast<py::ssize_t>(result.trace.size());
  auto time = new_array({n});
  auto position = new_array({n, 3});
  auto force = new_array({n, 3});
  py::array_t<std::uint8_t> state(n);
  py::array_t<std::int64_t> stroke(n);
  py::array_t<std::int64_t> element(n);
  py::array_t<std::int64_t> attempt(n);
  py::array_t<std::uint8_t> rewritten(n);
  auto tw = time.mutable_unchecked<1>();
  auto pw = position.mutable_unchecked<2>();
  auto fw = force.mutable_unchecked<2>();
  auto sw = state.mutable_unchecked<1>();
  auto aw = stroke.mutable_unchecked<1>();
  auto ew = element.mutable_unchecked<1>();
  auto tw_attempt = attempt.mutable_unchecked<1>();
  auto rw_rewritten = rewritten.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const TrialSample& s = result.trace[static_cast<std::size_t>(i)];
    tw(i) = s.time_s;
    for (py::ssize_t k = 0; k < 3; ++k) {
      pw(i, k) = s.position_m[static_cast<Eigen::Index>(k)];
      fw(i, k) = s.force_n[static_cast<Eigen::Index>(k)];
    }
    sw(i) = static_cast<std::uint8_t>(s.state);
    aw(i) = static_cast<std::int64_t>(s.stroke);
    ew(i) = static_cast<std::int64_t>(s.element);
    tw_attempt(i) = static_cast<std::int64_t>(s.attempt);
    rw_rewritten(i) = s.rewritten ? 1 : 0;
  }
  const auto strokes = static_cast<py::ssize_t>(result.metrics.per_stroke.size());
  py::array_t<std::int64_t> ranges({strokes, py::ssize_t{2}});
  auto rw = ranges.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < strokes; ++i) {
    const StrokeMetrics& m = result.metrics.per_stroke[static_cast<std::size_t>(i)];
    // Without a trace there is nothing to index: empty ranges.
    rw(i, 0) = n > 0 ? static_cast<std::int64_t>(m.trace_begin) : 0;
    rw(i, 1) = n > 0 ? static_cast<std::int64_t>(m.trace_end) : 0;
  }
  // Read-only: the metrics, the record and a teacher recorded from it are the trace as it was written.
  return PyTrialResult{read_only(time),
                       read_only(position),
                       read_only(force),
                       read_only(state),
                       read_only(stroke),
                       read_only(element),
                       read_only(attempt),
                       read_only(rewritten),
                       read_only(ranges),
                       std::move(metrics),
                       std::move(scene),
                       {},
                       {}};
}

// Runs `trial` (which runs with `inputs`) without the GIL. Ctrl-C: every 50 ms of wall clock the runner's
// thread takes the GIL and lets Python run its signal handlers; a KeyboardInterrupt (or any exception a
// handler raises) ends the trial at the next tick and is raised once the device is shut down.
template <typename Trial>
TrialRun run_interruptible(TrialRunInputs& inputs, Trial&& trial) {
  SignalPoll poll;
  inputs.should_stop = [&poll] { return poll.interrupted(); };
  TrialRun run;
  {
    py::gil_scoped_release release;
    run = trial();
  }
  poll.raise_if_interrupted();
  return run;
}

// One description of the arguments simulate_trial and run_trial share, in their Python order after each
// function's own leading arguments: X(C++ type, Python name, default). It makes the TrialArguments
// fields, the C++ parameters and the py::arg list of both functions.
#define CALLIGRAPHY_TRIAL_ARGUMENTS(X)                                      \
  X(Annotated<WriterTag>, writer, "novice")                                 \
  X(PyArgument<bool>, guidance, true)                                       \
  X(PyArgument<double>, rate_hz, 1000.0)                                    \
  X(PyArgument<std::uint64_t>, seed, 0)                                     \
  X(std::optional<PyArgument<CharacterSource>>, library, py::none())        \
  X(std::optional<PyArgument<ForceLawParameters>>, force_law, py::none())   \
  X(PyArgument<double>, max_duration_s, 300.0)                              \
  X(PyArgument<bool>, keep_trace, true)                                     \
  X(std::optional<Annotated<WriterParamsTag>>, writer_params, py::none())   \
  X(std::optional<PyArgument<GuidanceMode>>, guidance_mode, py::none())     \
  X(std::optional<PyArgument<double>>, guidance_gain, py::none())           \
  X(std::optional<Annotated<TeacherTag>>, teacher, py::none())              \
  X(std::optional<PyArgument<std::int64_t>>, hint_after_misses, py::none()) \
  X(std::optional<PyArgument<std::int64_t>>, assist_after_misses, py::none())

#define CALLIGRAPHY_TRIAL_FIELD(type, name, default_value) type name;
#define CALLIGRAPHY_TRIAL_PARAMETER(type, name, default_value) , const type& name
#define CALLIGRAPHY_TRIAL_VALUE(type, name, default_value) name,
#define CALLIGRAPHY_TRIAL_PY_ARG(type, name, default_value) , py::arg(#name) = default_value

struct TrialArguments {
  CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_FIELD)
};

// The teacher's samples for replay guidance: a TeacherRecording made on the scene's characters
// (`label`), or a list of TeacherSample.
std::vector<TeacherSample> teacher_samples(const py::object& teacher, const std::string& label) {
  if (py::isinstance<TeacherRecording>(teacher)) {
    const TeacherRecording& recording = teacher.cast<const TeacherRecording&>();
    try {
      require_teacher_for(recording, label);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("teacher: ") + e.what());
    }
    return recording.samples;
  }
  if (py::isinstance<py::str>(teacher) || !py::isinstance<py::sequence>(teacher))
    throw_type_error("teacher", "a TeacherRecording or a list of TeacherSample", teacher);
  return convert_named<std::vector<TeacherSample>>(teacher, "teacher");
}

// Guidance: `guidance_mode` (else replay when a teacher is given, else the force law's mode) replaces the
// force law's guidance law by that mode's defaults unless it is already of that mode; `guidance_gain` and the
// teacher's samples then set the fading gain and the replay's teacher.
void apply_guidance(const TrialArguments& a, const std::string& label, ForceLawParameters& force) {
  force.guidance = take(a.guidance, "guidance");
  std::optional<GuidanceMode> mode;
  if (a.guidance_mode) {
    mode = take(*a.guidance_mode, "guidance_mode");
  } else if (a.teacher && !a.teacher->object.is_none()) {
    mode = GuidanceMode::replay;
  }
  if (mode && mode_of(force.guidance_law) != *mode) force.guidance_law = default_guidance_law(*mode);
  if (a.guidance_gain) {
    auto* fading = std::get_if<FadingGuidance>(&force.guidance_law);
    if (fading == nullptr) {
      throw InvalidArgument(std::string("guidance_gain: applies to guidance_mode 'fading' only, got '") +
                            to_string(mode_of(force.guidance_law)) + "'");
    }
    fading->gain = take(*a.guidance_gain, "guidance_gain");
    try {
      validate_guidance_law(force.guidance_law, force.constraint_radius_m);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("guidance_gain: ") + e.what());
    }
  }
  auto* replay = std::get_if<ReplayGuidance>(&force.guidance_law);
  if (a.teacher && !a.teacher->object.is_none()) {
    if (replay == nullptr) {
      throw InvalidArgument(std::string("teacher: only the 'replay' guidance mode uses a teacher, got "
                                        "guidance_mode '") +
                            to_string(mode_of(force.guidance_law)) + "'");
    }
    replay->teacher_trajectory = teacher_samples(a.teacher->object, label);
  }
  if (replay != nullptr && replay->teacher_trajectory.empty()) {
    throw InvalidArgument(
        "guidance_mode 'replay' needs teacher= (a TeacherRecording or a list of TeacherSample)");
  }
}

// The trial behind simulate_trial and run_trial: `device_name` empty runs on a SimulatedDevice made from
// `device`; else on the registry's device of that name, paced by `pacing`.
PyTrialResult trial_py(const std::string& device_name, TrialPacing pacing,
                       const Annotated<TrialCharactersTag>& characters, const TrialArguments& a,
                       const std::optional<PyArgument<SimulatedDeviceParameters>>& device,
                       const std::optional<PyArgument<SafetyChainParameters>>& safety,
                       const std::optional<PyArgument<PassivityParameters>>& passivity,
                       const std::optional<PyArgument<double>>& watchdog_s = std::nullopt) {
  TrialOptions options;
  options.pacing = pacing;
  if (a.force_law) options.force = take(*a.force_law, "force_law");
  SimulationOptions simulation;
  std::vector<WriterSetting> given_settings;  // writer_params as given, stated as --writer-param states them
  simulation.writer = writer_with_settings(
      a.writer.object, a.writer_params ? a.writer_params->object : py::none(), &given_settings);
  options.rate_hz = take(a.rate_hz, "rate_hz");
  simulation.seed = take(a.seed, "seed");
  options.max_duration_s = take(a.max_duration_s, "max_duration_s");
  // The trace is always recorded: the metrics are taken from it (trial_writing_metrics); keep_trace=False
  // only leaves the returned arrays empty.
  const bool keep_trace = take(a.keep_trace, "keep_trace");
  options.keep_trace = true;
  if (device) simulation.device = take(*device, "device");
  if (safety) options.safety = take(*safety, "safety");
  if (passivity) options.passivity = take(*passivity, "passivity");

  py::object scene_object;
  if (py::isinstance<Scene>(characters.object)) {
    scene_object = characters.object;
  } else {
    const CharacterSource source = a.library ? take(*a.library, "library") : CharacterSource::embedded();
    scene_object = py::cast(Scene::lay_out(characters_from(characters.object, source, "characters")));
  }
  const Scene& scene = scene_object.cast<const Scene&>();
  std::string label;
  for (const PlacedCharacter& c : scene.characters) label += encode_utf8(c.code_point);

  apply_guidance(a, label, options.force);
  // The stroke acceptance's miss counts, the specification's fields of the same names, over force_law's.
  if (a.hint_after_misses)
    options.force.acceptance.hint_after_misses =
        static_cast<double>(take(*a.hint_after_misses, "hint_after_misses"));
  if (a.assist_after_misses)
    options.force.acceptance.assist_after_misses =
        static_cast<double>(take(*a.assist_after_misses, "assist_after_misses"));
  options.validate();
  simulation.validate();

  // The trial specification of these arguments, made a whole trial by its one builder and run by its one
  // runner (whole_trial.hpp, trial_spec_runner.hpp), as `calligraphy trial` runs its options. What a
  // specification does not state goes to the builder as parts of the whole trial (force-law, safety and
  // passivity tuning, the simulated device's parameters), or to the runner as its runtime inputs (the
  // device, a WriterProfile object in the hand maker, a teacher given as samples).
  TrialSpec spec;
  spec.characters = label;
  spec.device = device_name.empty() ? std::string("simulated") : device_name;
  spec.guidance = options.force.guidance;
  const GuidanceLaw& law = options.force.guidance_law;
  // The mode the caller asked for (guidance_mode=, or a teacher's replay) is stated even with guidance off,
  // so that the specification's one check refuses the contradiction as `trial --guidance off --guidance-mode`
  // is refused, rather than the trial running unguided under a record that says 'fixed'.
  const bool mode_asked = a.guidance_mode || (a.teacher && !a.teacher->object.is_none());
  if (spec.guidance || mode_asked) spec.guidance_mode = mode_of(law);
  if (spec.guidance) {
    if (const auto* fading = std::get_if<FadingGuidance>(&law)) spec.guidance_gain = fading->gain;
    if (const auto* assist = std::get_if<AssistAsNeededGuidance>(&law)) spec.assist_band_m = assist->band_m;
    if (const auto* amplify = std::get_if<ErrorAmplificationGuidance>(&law))
      spec.amplification_gain = amplify->gain;
    if (const auto* timing = std::get_if<TimingGuidance>(&law)) spec.timing_speed_m_s = timing->speed_m_s;
  }
  // The profile it starts from, by name when it is one of the named ones (else the specification's default),
  // and the settings that make it the profile given (writer_params, or a WriterProfile of other values): the
  // specification alone then states the writer that wrote, as `--writer-profile` and `--writer-param` do.
  // The profile itself is also an input below, and the record keeps it whole.
  // A WriterProfile's own differences from its named profile come first, then writer_params as given, in
  // turn (a setting equal to the profile's value too), as `--writer-param` states them: the same request
  // makes the same record on both sides.
  const std::string& profile_name = simulation.writer.name;
  const auto named = writer_profile_names();
  if (std::find(named.begin(), named.end(), profile_name) != named.end()) spec.writer_profile = profile_name;
  const WriterProfile base = writer_profile(spec.writer_profile);
  const WriterProfile before_params = writer_with_settings(a.writer.object, py::none());
  for (const std::string& key : writer_parameter_names()) {
    const double value = writer_parameter(before_params, key);
    if (value != writer_parameter(base, key)) spec.writer_parameters.push_back({key, value});
  }
  spec.writer_parameters.insert(spec.writer_parameters.end(), given_settings.begin(), given_settings.end());
  spec.seed = simulation.seed;
  spec.rate_hz = options.rate_hz;
  spec.pacing = options.pacing;
  spec.max_duration_s = options.max_duration_s;
  spec.acceptance = options.force.acceptance;
  // The stall bound `trial --watchdog-ms` sets; the specification's one check refuses it in lock-step.
  if (watchdog_s) spec.watchdog_s = take(*watchdog_s, "watchdog_s");
  // A replay's teacher is given as samples (TrialRunInputs::teacher), below.
  const auto checked = calligraphy::Checked<TrialSpec>::check(
      spec, spec.guidance_mode == GuidanceMode::replay ? TeacherSource::samples : TeacherSource::file);
  // The device first (the registry's by name, or a simulated one of the given physics): the whole trial is
  // built for it.
  std::unique_ptr<HapticDevice> trial_device = device_name.empty()
                                                   ? std::make_unique<SimulatedDevice>(simulation.device)
                                                   : python_device_registry().create(device_name);
  // Auto pacing is lock-step on a device the simulated writer moves, and lock-step has no wall clock to
  // bound: a stall bound given there is refused, as `trial --watchdog-ms` is (the record would be invalid).
  const bool lock_step = spec.pacing == TrialPacing::lock_step ||
                         (spec.pacing == TrialPacing::automatic && trial_device->hand_port() != nullptr);
  if (watchdog_s && lock_step) {
    throw InvalidArgument(
        "watchdog_s: applies to real-time pacing only (pacing='real-time' or a hardware "
        "device); '" +
        trial_device->info().model + "' runs lock-step, with no wall clock to bound");
  }
  TrialRunInputs inputs;
  inputs.device = trial_device.get();
  inputs.host_process = true;  // the interpreter is the application: no memory locking, no SCHED_FIFO
  SimulatedWriting writing(spec, simulation.writer);
  inputs.hand_maker = &writing;
  if (const auto* replay = std::get_if<ReplayGuidance>(&law)) inputs.teacher = replay->teacher_trajectory;
  // The whole trial, through the one builder: the force law as given (no stiffness fitted to the device),
  // the safety chain and passivity controller as given.
  const auto whole =
      build_whole_trial(checked, trial_device->info(),
                        {.force_law = options.force,
                         .safety = options.safety,
                         .passivity = options.passivity,
                         .simulated_device = device ? std::optional(simulation.device) : std::nullopt});
  TrialRun run = run_interruptible(inputs, [&] { return run_whole_trial(whole, scene, inputs); });
  TrialResult& result = run.result;
  TrialDescription description;
  description.characters = label;
  description.guidance = options.force.guidance;
  description.writer = "simulated";
  description.seed = simulation.seed;
  description.rate_hz = options.rate_hz;
  if (!device_name.empty()) description.device = device_name;
  // The guidance and writer provenance, as `calligraphy trial --json` gives it.
  description.guidance_mode = mode_of(law);
  if (const auto* fading = std::get_if<FadingGuidance>(&law)) description.guidance_gain = fading->gain;
  if (description.guidance_mode == GuidanceMode::replay) {
    description.teacher_characters =
        label;  // a recording was checked against them; samples are taken as given
  }
  description.writer_profile = simulation.writer.name.empty() ? "custom" : simulation.writer.name;
  // writer_params as `--writer-param` prints them: "key=value", the value in its shortest digits
  for (const WriterSetting& setting : given_settings)
    description.writer_parameters.push_back(writer_setting_text(setting));
  // The whole specification that ran, with a simulated device's own physics: rerun_trial runs it again.
  RecordedTrial recorded = recorded_trial(spec, run, writing, scene);
  // Only physics of the caller's own: without `device=` the simulated device is the registry's.
  if (device) recorded.simulated_device = simulation.device;
  description.specification_json = recorded_trial_json(recorded);
  if (!keep_trace) result.trace = {};
  PyTrialResult out = to_python(result, trial_metrics(description, result, run.metrics), scene_object);
  out.writer = simulation.writer;
  out.writer_log = writing.log();
  return out;
}

PyTrialResult simulate_trial_py(const Annotated<TrialCharactersTag>& characters
                                    CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_PARAMETER),
                                const std::optional<PyArgument<SimulatedDeviceParameters>>& device,
                                const std::optional<PyArgument<SafetyChainParameters>>& safety,
                                const std::optional<PyArgument<PassivityParameters>>& passivity) {
  const TrialArguments arguments{CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_VALUE)};
  return trial_py({}, TrialPacing::lock_step, characters, arguments, device, safety, passivity);
}

PyTrialResult run_trial_py(
    const Annotated<TrialCharactersTag>& characters, const PyArgument<std::string>& device,
    const PyArgument<std::string>& pacing CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_PARAMETER),
    const std::optional<PyArgument<double>>& watchdog_s) {
  const TrialArguments arguments{CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_VALUE)};
  const std::string name = take(device, "device");
  if (name.empty()) throw InvalidArgument("device: a device name of list_devices() is needed");
  const TrialPacing chosen = parse_trial_pacing(take(pacing, "pacing"));
  return trial_py(name, chosen, characters, arguments, std::nullopt, std::nullopt, std::nullopt, watchdog_s);
}

// The trial a record states (a TrialResult's metrics, a trial record as a dict, or a record's file), run
// again as it ran.
// The record `record` names (a dict or a path), read and checked by the one reader (recorded_trial.hpp).
// The JSON pointer and value of the first float of `value` that JSON cannot hold (nan, inf): a dict holding
// one is refused naming that value, as the reader names a value out of its range, rather than as JSON text
// the caller never wrote, cut at a byte offset of it.
std::optional<std::pair<std::string, std::string>> non_finite_value(const py::handle& value,
                                                                    const std::string& pointer) {
  if (py::isinstance<py::float_>(value)) {
    if (std::isfinite(value.cast<double>())) return std::nullopt;
    return std::make_pair(pointer, py::repr(value).cast<std::string>());
  }
  const auto child = [&](const std::string& name) {
    std::string at = pointer;
    at.append("/");
    for (const char c : name) at.append(c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c));  // RFC 6901
    return at;
  };
  if (py::isinstance<py::dict>(value)) {
    for (const auto& [key, item] : value.cast<py::dict>()) {
      auto found = non_finite_value(item, child(convert_named<std::string>(py::str(key), "record key")));
      if (found) return found;
    }
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::size_t i = 0;
    for (const py::handle item : value) {
      auto found = non_finite_value(item, child(std::to_string(i++)));
      if (found) return found;
    }
  }
  return std::nullopt;
}

RecordedTrial read_record_py(const py::object& record) {
  if (py::isinstance<py::dict>(record)) {
    if (const auto found = non_finite_value(record, "")) {
      std::string message = "record: ";
      message.append(found->first).append(": expected a finite number, got ").append(found->second);
      throw DataError(message);
    }
    const std::string text = py::module_::import("json").attr("dumps")(record).cast<std::string>();
    return read_recorded_trial(text, "record");
  }
  if (py::isinstance<py::str>(record)) {
    // A record's JSON text passed for its path: say so, rather than naming the text as a missing file.
    const std::string text = convert_named<std::string>(record, "record");  // a lone surrogate: a wrong value
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    std::error_code no_file;  // a text too long for a path is not a file either
    if (first != std::string::npos && (text[first] == '{' || text[first] == '[') &&
        !std::filesystem::exists(std::filesystem::path(text), no_file))
      throw py::type_error(
          "record: a record's JSON text, not a path: give json.loads(text) (a dict) or the record's path");
  }
  if (py::isinstance<py::str>(record) || py::isinstance<py::bytes>(record) ||
      py::isinstance(record, py::module_::import("os").attr("PathLike")))
    return read_study_recorded_trial(convert_named<std::filesystem::path>(record, "record").string());
  throw_type_error("record", "a dict (TrialResult.metrics, a trial record) or a record's path", record);
}

// The specification a record states, checked as a re-run checks it, as the library writes it back.
py::dict check_trial_record_py(const py::object& record) {
  RecordedTrial recorded = read_record_py(record);
  // A replay's teacher is given when it runs (the file the record names, or samples): it is not read here.
  (void)calligraphy::Checked<TrialSpec>::check(
      recorded.spec, recorded.spec.teacher.empty() ? TeacherSource::samples : TeacherSource::file);
  return py::module_::import("json").attr("loads")(recorded_trial_json(recorded)).cast<py::dict>();
}

PyTrialResult rerun_trial_py(const py::object& record,
                             const std::optional<PyArgument<CharacterSource>>& library,
                             const std::optional<Annotated<TeacherTag>>& teacher) {
  RecordedTrial recorded = read_record_py(record);
  const CharacterSource source = library ? take(*library, "library") : CharacterSource::embedded();
  py::object scene_object = py::cast(
      Scene::lay_out(characters_from(py::str(recorded.spec.characters), source, "record"), recorded.layout));
  const Scene& scene = scene_object.cast<const Scene&>();
  TrialRunInputs inputs;
  inputs.registry = &python_device_registry();
  inputs.host_process = true;
  if (teacher && !(recorded.spec.guidance_mode == GuidanceMode::replay && recorded.spec.guidance)) {
    // As `trial --spec RECORD --teacher FILE` refuses it: a teacher given to a trial that replays none.
    throw InvalidArgument(
        "teacher: the record's trial is not a replay (guidance " +
        std::string(recorded.spec.guidance ? to_string(recorded.spec.guidance_mode) : "off") + ")");
  }
  if (recorded.spec.guidance_mode == GuidanceMode::replay && recorded.spec.guidance) {
    if (teacher) {
      inputs.teacher = teacher_samples(teacher->object, recorded.spec.characters);
      recorded.spec.teacher.clear();  // the samples are the teacher
    } else if (!recorded.spec.teacher.empty()) {
      // The file the record names (a session's kept teacher, or the --teacher of `calligraphy trial`), read
      // and bound by its SHA-256 as `trial --spec` reads it.
      TeacherFile file =
          read_record_named_teacher(recorded, "record", "teacher=read_teacher_recording(FILE)");
      require_teacher_for(file.recording, recorded.spec.characters);
      inputs.teacher = std::move(file.recording.samples);
      recorded.spec.teacher.clear();  // its samples are the teacher now, as a teacher= given
    } else {
      throw InvalidArgument(
          "teacher: the record's trial is a replay and names no teacher's file; give its teacher (a "
          "TeacherRecording or a list of TeacherSample)");
    }
  }
  const auto checked = calligraphy::Checked<TrialSpec>::check(
      recorded.spec, inputs.teacher.empty() ? TeacherSource::file : TeacherSource::samples);
  SimulatedWriting writing = recorded_writing(recorded);
  inputs.hand_maker = &writing;
  TrialRun run = run_interruptible(inputs, [&] { return rerun_trial(recorded, checked, scene, inputs); });
  // A record changed since it was written runs as another trial: said as a RuntimeWarning, never silently.
  if (const std::vector<std::string> differences = rerun_differences(recorded, run.result);
      !differences.empty()) {
    if (PyErr_WarnEx(PyExc_RuntimeWarning, rerun_differences_text(recorded, differences).c_str(), 1) < 0)
      throw py::error_already_set();
  }
  TrialDescription description;
  description.characters = recorded.spec.characters;
  description.guidance = recorded.spec.guidance;
  description.writer = run.simulated_writer ? "simulated" : "person";
  description.seed = recorded.spec.seed;
  description.rate_hz = recorded.spec.rate_hz;
  description.device = recorded.spec.device;
  description.guidance_mode = mode_of(run.options.force.guidance_law);
  if (const auto* fading = std::get_if<FadingGuidance>(&run.options.force.guidance_law))
    description.guidance_gain = fading->gain;
  if (description.guidance_mode == GuidanceMode::replay)
    description.teacher_characters = recorded.spec.characters;
  if (run.simulated_writer) description.writer_profile = writing.profile().name;
  RecordedTrial ran = recorded_trial(recorded.spec, run, writing, scene);
  ran.simulated_device = recorded.simulated_device;
  description.specification_json = recorded_trial_json(ran);
  PyTrialResult out =
      to_python(run.result, trial_metrics(description, run.result, run.metrics), scene_object);
  out.writer = writing.profile();
  out.writer_log = writing.log();
  return out;
}

// A teacher's recording of a finished trial (teacher_recording_from_trace): its trace's times and pen
// positions, its characters, writer, device and rate.
TeacherRecording record_teacher_py(const PyTrialResult& result, const std::optional<PathLike>& path) {
  const auto time = result.time_s.unchecked<1>();
  const auto position = result.position_m.unchecked<2>();
  std::vector<TrialSample> trace(static_cast<std::size_t>(time.shape(0)));
  for (py::ssize_t i = 0; i < time.shape(0); ++i) {
    TrialSample& sample = trace[static_cast<std::size_t>(i)];
    sample.time_s = time(i);
    sample.position_m = Vec3(position(i, 0), position(i, 1), position(i, 2));
  }
  const py::dict& m = result.metrics;
  // The recording's writer is the simulated writer's profile, or "person" (teacher_recording.hpp).
  const std::string writer = m.contains("writer_profile") ? m["writer_profile"].cast<std::string>()
                                                          : m["writer"].cast<std::string>();
  TeacherRecording recording;
  try {
    recording =
        teacher_recording_from_trace(m["character"].cast<std::string>(), writer,
                                     m["device"].cast<std::string>(), m["rate_hz"].cast<double>(), trace);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("result: ") + e.what());
  }
  if (path) write_teacher_recording(recording, convert_named<std::filesystem::path>(path->object, "path"));
  return recording;
}

}  // namespace

void bind_trial(py::module_& m) {
  py::class_<PyTrialResult>(m, "TrialResult",
                            "A simulated trial: the trace, one row per servo tick (N ticks, empty when "
                            "keep_trace=False), and the metrics.")
      .def_readonly("time_s", &PyTrialResult::time_s, "(N,) float64, time [s]")
      .def_readonly("position_m", &PyTrialResult::position_m,
                    "(N, 3) float64, pen tip as read from the device [m]")
      .def_readonly("force_n", &PyTrialResult::force_n, "(N, 3) float64, commanded force [N]")
      .def_readonly("state", &PyTrialResult::state, "(N,) uint8, the InteractionState's int value")
      .def_readonly("stroke", &PyTrialResult::stroke, "(N,) int64, active stroke over the scene, 0-based")
      .def_readonly("element", &PyTrialResult::element,
                    "(N,) int64, active element within the stroke, 0-based")
      .def_readonly("attempt", &PyTrialResult::attempt,
                    "(N,) int64, the attempt at the stroke this tick belongs to, 1-based; 0 outside any")
      .def_readonly(
          "rewritten", &PyTrialResult::rewritten,
          "(N,) uint8, 1: part of an attempt at the stroke written again later (not the final writing)")
      .def_readonly("stroke_trace_range", &PyTrialResult::stroke_trace_range,
                    "(S, 2) int64, one row per stroke of the scene: [begin, end) of its last attempt in the "
                    "trace, the ticks its deviations are measured over (empty when not written or no trace)")
      .def_readonly(
          "metrics", &PyTrialResult::metrics,
          "dict with exactly the keys of `calligraphy trial --json`, from the same code (deviations "
          "in mm, times in s, forces in N; 'per_stroke' a list of dicts)")
      .def_property_readonly(
          "scene", [](const PyTrialResult& r) { return Annotated<SceneTag>{r.scene}; },
          "the Scene the trial was written on (metres)")
      .def_readonly("writer", &PyTrialResult::writer,
                    "the WriterProfile the simulated writer wrote with (after writer_params)")
      .def_readonly("writer_log", &PyTrialResult::writer_log,
                    "the simulated writer's WriterLog (attempts, order and direction errors, refusals), for "
                    "RepetitionOutcome.from_log; None on a device a person moves")
      // The tables are made in Python (calligraphy/frames.py), where pandas is an optional import.
      .def(
          "to_dataframe",
          [](const py::object& self) {
            return Annotated<DataFrameTag>{
                py::module_::import("calligraphy.frames").attr("trial_dataframe")(self)};
          },
          "A pandas.DataFrame with one row per servo tick, its columns named as trace_columns() names them: "
          "t_s [s], x_m, y_m, z_m [m], fx_n, fy_n, fz_n [N], state (categorical 'SS', 'AS', 'CS', 'WS'), "
          "stroke, element (0-based), attempt (1-based, 0 outside any), rewritten (1: written again later). "
          "Raises ImportError without pandas.")
      .def(
          "per_stroke_dataframe",
          [](const py::object& self) {
            return Annotated<DataFrameTag>{
                py::module_::import("calligraphy.frames").attr("per_stroke_dataframe")(self)};
          },
          "A pandas.DataFrame with one row per stroke, indexed by the stroke over the scene (0-based): "
          "character, acronym, typical_id, written, backwards, mean_deviation_m, max_deviation_m, frechet_m, "
          "dtw_m [m], time_s [s], completed, attempts. Raises ImportError without pandas.");

  m.def("simulate_trial", &simulate_trial_py,
        py::arg("characters") CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_PY_ARG),
        py::arg("device") = py::none(), py::arg("safety") = py::none(), py::arg("passivity") = py::none(),
        py::call_guard<ForwardLog>(),
        R"(Runs a whole guided writing trial lock-step on the simulated device with a simulated writer,
as `calligraphy trial` does (run_simulated_trial, include/calligraphy/trial/trial.hpp).
Deterministic for a seed; the GIL is released while it runs.

characters: a str of one or more characters (loaded from `library`, default every character),
            a Character, a sequence of Characters (written left to right), or a Scene.
writer: 'novice', 'skilled', 'foreign' or a WriterProfile; writer_params: {'key': value} set on it
by name (writer_parameter_names(), docs/writer.md). guidance: in-plane guidance on or off (the paper
force stays). guidance_mode: 'fixed' (eq. 8), 'fading' (eq. 8 times guidance_gain in [0, 1]),
'replay' (follow `teacher` in time), 'assist-as-needed', 'error-amplification' or 'timing'
(docs/force-rendering.md, "Guidance modes"); None keeps force_law's, or 'replay' when a teacher is given.
teacher: a TeacherRecording of the same characters (record_teacher) or a list of TeacherSample.
rate_hz: servo rate [Hz], 100..100000. seed: int >= 0. max_duration_s: simulated time limit [s],
> 0, at most 86400 s (a day) and 10^7 ticks (rate_hz * max_duration_s).
hint_after_misses, assist_after_misses: refused attempts at a stroke after which it is shown as a hint,
and after which it is demonstrated and credited as assisted (ints in 0..1000, 0: never; None
keeps force_law's acceptance's, 3 and 5 by default), as `calligraphy trial --hint-after-misses N
--assist-after-misses N` (docs/stroke-acceptance.md).
force_law: ForceLawParameters (its guidance fields are replaced by the arguments given). device:
SimulatedDeviceParameters. safety: SafetyChainParameters (0 forces take the device's figures).
passivity: PassivityParameters. keep_trace: False leaves the arrays empty (faster, metrics only).
Returns a TrialResult (with .writer and .writer_log). Raises CharacterNotFound (a KeyError),
InvalidArgument (a ValueError) for values out of range, an unknown writer or writer_params key (named),
a teacher of other characters or replay without a teacher; TypeError naming the argument for a value
of the wrong type.)");
  m.def("run_trial", &run_trial_py, py::arg("characters"), py::arg("device") = "simulated",
        py::arg("pacing") = "auto" CALLIGRAPHY_TRIAL_ARGUMENTS(CALLIGRAPHY_TRIAL_PY_ARG),
        py::arg("watchdog_s") = py::none(), py::call_guard<ForwardLog>(),
        R"(Runs a whole guided writing trial on the device called `device` in list_devices(), as
`calligraphy trial --device NAME` does (run_trial, include/calligraphy/trial/runner.hpp): 'simulated' is
moved by the simulated `writer` (the command line's Phantom emulator, 'emulated-phantom', is not among the
module's devices); a hardware device is moved by a person and runs in real time on the servo loop's own
thread. The GIL is released while it runs; Ctrl-C ends the trial at
the next tick (forces off, the device closed) and raises KeyboardInterrupt.

pacing: 'auto' (lock-step for a device a simulated writer moves, real time otherwise), 'lock-step' or
'real-time' (the spellings of `calligraphy trial --pacing` and of protocols). rate_hz: servo rate [Hz] (at most 10000 in real time).
watchdog_s: the real-time loop's stall bound [s], a whole number of milliseconds in [0, 60] (0: off), the
specification's `watchdog_s` (`calligraphy trial --watchdog-ms`); None: 0.05, the Phantom's own command
watchdog; refused with lock-step pacing. The other arguments as for
simulate_trial. Returns a TrialResult whose metrics carry `end_reason`. Raises DeviceNotFound (a
LookupError) naming the devices there are, InvalidArgument, RealtimeError, CommunicationError.)");
  m.def("rerun_trial", &rerun_trial_py, py::arg("record"), py::arg("library") = py::none(),
        py::arg("teacher") = py::none(), py::call_guard<ForwardLog>(),
        R"(Runs again the trial a record states (include/calligraphy/trial/recorded_trial.hpp): its whole
specification, the force law with its guidance law's values, the safety chain, the passivity controller,
the simulated writer's profile and seed and a simulated device's physics, on the characters of `library`
(default every character) laid out as recorded. On the simulated device the trace is the same bit for bit.

record: a TrialResult's `metrics` (simulate_trial, run_trial), a trial record read as a dict (`calligraphy
trial --json`, a study session's trials/*.json), or the path of such a file. teacher: a replay's teacher (a
TeacherRecording or a list of TeacherSample), which records name but do not hold; without it, the file the
record names is read as `calligraphy trial --spec` reads it (a session's record: the teacher kept in its
session folder; a `trial --json` record: its --teacher, a relative name from the working folder). Returns a
TrialResult. Raises DataError naming the record and the JSON pointer of a value at fault, a record without a
specification (written before records held one) or of another version, or a teacher's file that cannot be
read or is not the recording the replay ran on (naming it and both SHA-256); InvalidArgument when the
characters placed are not the recorded ones (other character data), a replay naming no teacher's file
given none, or a teacher given to a trial that is not a replay (as `trial --spec RECORD --teacher FILE`);
CharacterNotFound; TypeError for a record of another type or its JSON text given as a path. Warns
(RuntimeWarning) when a simulated writer's re-run gives other figures than the run the record states: the
record changed since it was written (a seed past 2^53 rounded by a tool), or another library.)");
  m.def(
      "check_trial_record", &check_trial_record_py, py::arg("record"),
      R"(Checks the trial a record states, as rerun_trial and `calligraphy trial --spec RECORD --check` check
it, without running it: every field in its range (the one schema, `calligraphy schema record`), every
contradiction refused. record: as rerun_trial takes it. Returns the record's specification as the library
writes it back (a dict: "format", "version", "trial", "force_law", ...; enumerations by their one spelling),
which check_trial_record and rerun_trial take again. Raises DataError naming the record and the JSON pointer
of a value at fault (of another type or out of its range) and of a contradiction between fields, with the
field; TypeError for a record of another type.)");
  m.def("record_teacher", &record_teacher_py, py::arg("result"), py::arg("path") = py::none(),
        R"(A teacher's recording of a trial (teacher_recording_from_trace,
include/calligraphy/trial/teacher_recording.hpp): the pen's times [s] and positions [m] of every tick,
its characters, writer, device and rate, for simulate_trial(..., teacher=recording) on the same
characters. With `path` it is also written there as JSON, atomically. Raises InvalidArgument when the
trial kept no trace (keep_trace=False), Error naming the path when it cannot be written.)");
}

#undef CALLIGRAPHY_TRIAL_PY_ARG
#undef CALLIGRAPHY_TRIAL_VALUE
#undef CALLIGRAPHY_TRIAL_PARAMETER
#undef CALLIGRAPHY_TRIAL_FIELD
#undef CALLIGRAPHY_TRIAL_ARGUMENTS

}  // namespace calligraphy::python
