// `calligraphy trial CHARS ...`: a whole guided writing trial on any registered device (the simulated one
// by default). The options are the trial specification's (trial_spec.hpp), parsed and validated by it, and
// the trial is run by its one runner (run_trial_spec): lock-step for devices a simulated writer moves, on
// the real-time ServoLoop otherwise or with --pacing real-time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/teacher_recording.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/sim/writer_profile.hpp"
#include "calligraphy/study/recorded_trial.hpp"
#include "calligraphy/trial/trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/signals.hpp"
#include "cli/writer_options.hpp"

namespace calligraphy::cli {
namespace {

struct TrialCommand {
  std::string characters;
  std::string device = "simulated";
  std::string guidance = "on";
  std::string writer;  // person or simulated; empty: the device's own (writer_for_device)
  std::string writer_profile = "novice";
  const CLI::Option* profile_option = nullptr;
  std::vector<std::string> writer_parameters;  // "key=value", applied in turn
  std::string guidance_mode = "fixed";
  std::string guidance_gain_text;       // "": the specification's default
  std::string assist_band_text;         // "": the specification's default
  std::string amplification_gain_text;  // "": the specification's default
  std::string timing_speed_text;        // "": the specification's default
  std::string teacher;                  // replay: the recording's path
  std::string record;                   // write the trial as a teacher's recording
  std::uint64_t seed = 0;
  std::string rate_text = "1000";  // given to the specification's parser as it was typed
  std::string max_duration_text;   // "": the specification's default
  std::string pacing = "auto";
  std::string realtime = "ignore";
  std::int64_t watchdog_ms = std::llround(ServoLoopOptions{}.stall_timeout_s * 1000.0);
  const CLI::Option* watchdog_option = nullptr;  // given on the command line when its count() > 0
  LibraryOptions library;
  std::string json, svg, csv;
  std::string spec_file;          // --spec: a trial record (or its specification) to run again
  const CLI::App* app = nullptr;  // to ask which options were given
};

// The options that state a trial: with --spec the record states it, and each of these would be ignored.
constexpr const char* kSpecificationOptions[] = {"--device",        "--guidance",    "--guidance-mode",
                                                 "--guidance-gain", "--assist-band", "--amplification-gain",
                                                 "--timing-speed",  "--writer",      "--writer-profile",
                                                 "--writer-param",  "--seed",        "--rate",
                                                 "--max-duration",  "--pacing",      "--realtime",
                                                 "--watchdog-ms",   "--record"};

// --spec: the record's specification, with this command's outputs (and a replay's --teacher when given).
RecordedTrial recorded_from(const TrialCommand& command) {
  if (command.app->count("CHARS") > 0) {
    throw UsageError("CHARS: the characters come from --spec " + command.spec_file +
                     "; give one or the other");
  }
  for (const char* option : kSpecificationOptions) {
    if (command.app->count(option) > 0) {
      throw UsageError(std::string(option) + ": the trial is stated by --spec " + command.spec_file +
                       "; with it go only --json, --csv, --svg, --teacher and the character data options");
    }
  }
  RecordedTrial recorded = read_recorded_trial_file(command.spec_file);
  if (!command.teacher.empty()) {
    if (recorded.spec.guidance_mode != GuidanceMode::replay) {
      throw UsageError("--teacher: the trial in --spec " + command.spec_file +
                       " is not a replay (guidance mode " + to_string(recorded.spec.guidance_mode) + ")");
    }
    recorded.spec.teacher = command.teacher;
  }
  recorded.spec.json_file = command.json;
  recorded.spec.csv_file = command.csv;
  recorded.spec.svg_file = command.svg;
  return recorded;
}

// The specification of a record with this command's outputs, checked once: it is what runs.
Checked<TrialSpec> checked_spec(const TrialCommand& command, const RecordedTrial& recorded) {
  try {
    return Checked<TrialSpec>::check(recorded.spec);
  } catch (const InvalidArgument& e) {
    // A session's replay ran on its teacher's samples: the record names no file.
    throw UsageError(std::string("--spec ") + command.spec_file + ": " + e.what() +
                     (recorded.spec.guidance_mode == GuidanceMode::replay
                          ? " (give the teacher's recording with --teacher)"
                          : ""));
  }
}

// The trial specification of the command line: every option given goes through the specification's one
// parser (trial_spec.hpp) and its one check; an error there is a usage error naming the option.
Checked<TrialSpec> spec_from(const TrialCommand& command) {
  std::vector<std::string> args{command.characters};
  const auto add = [&args](const char* option, const std::string& value) {
    args.emplace_back(option);
    args.push_back(value);
  };
  add("--device", command.device);
  add("--guidance", command.guidance);
  add("--guidance-mode", command.guidance_mode);
  if (!command.guidance_gain_text.empty()) add("--guidance-gain", command.guidance_gain_text);
  if (!command.assist_band_text.empty()) add("--assist-band", command.assist_band_text);
  if (!command.amplification_gain_text.empty()) add("--amplification-gain", command.amplification_gain_text);
  if (!command.timing_speed_text.empty()) add("--timing-speed", command.timing_speed_text);
  if (!command.teacher.empty()) add("--teacher", command.teacher);
  if (!command.writer.empty()) add("--writer", command.writer);
  if (command.profile_option->count() > 0) add("--writer-profile", command.writer_profile);
  for (const std::string& setting : command.writer_parameters) add("--writer-param", setting);
  add("--seed", std::to_string(command.seed));
  add("--rate", command.rate_text);
  add("--pacing", command.pacing);
  add("--realtime", command.realtime);
  if (command.watchdog_option->count() > 0) add("--watchdog-ms", std::to_string(command.watchdog_ms));
  if (!command.max_duration_text.empty()) add("--max-duration", command.max_duration_text);
  if (!command.json.empty()) add("--json", command.json);
  if (!command.csv.empty()) add("--csv", command.csv);
  if (!command.svg.empty()) add("--svg", command.svg);
  if (!command.record.empty()) add("--record", command.record);
  try {
    return trial_spec_from_args(args);
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

// What the trial's JSON and table say of it: the specification and the device it ran on.
TrialDescription describe(const TrialSpec& spec, const TrialRun& run, const SimulatedWriting& writing,
                          const DeviceListing& device) {
  // The report calls a person "human"; the simulated writer by its profile.
  TrialDescription description{
      spec.characters,  spec.guidance, run.simulated_writer ? spec.writer_profile : "human",
      spec.seed,        spec.rate_hz,  device.name,
      device.info.model};
  description.guidance_mode = spec.guidance_mode;
  description.guidance_gain = spec.guidance_gain;
  if (spec.guidance_mode == GuidanceMode::replay) {
    description.teacher_file = spec.teacher;
    description.teacher_characters = spec.characters;  // the runner refuses a recording of others
  }
  if (run.simulated_writer) {
    description.writer_profile = writing.profile().name;
    description.writer_parameters = trial_spec_field_text(spec, "writer_parameters");
  }
  return description;
}

// A replay's teacher: the recording --teacher names, of these characters.
std::vector<TeacherSample> teacher_samples(const TrialSpec& spec) {
  TeacherRecording recording = read_teacher_recording(spec.teacher);
  try {
    require_teacher_for(recording, spec.characters);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("teacher (--teacher) " + spec.teacher + ": " + e.what());
  }
  return std::move(recording.samples);
}

// Writes each output given; one that fails is reported on stderr and does not keep the others from being
// written. Returns whether all were written.
bool write_trial_outputs(const TrialSpec& spec, const TrialDescription& description, const Scene& scene,
                         const TrialResult& result, const WritingMetrics& writing) {
  bool all_written = true;
  const auto write = [&](const std::string& path, const auto& text) {
    if (path.empty()) return;
    try {
      write_output(path, text());
    } catch (const Error& e) {  // DataError naming the path and the reason
      print_error_line("calligraphy trial", "error", e.what());
      all_written = false;
    } catch (const std::bad_alloc&) {  // a trace too large to format in memory
      print_error_line("calligraphy trial", "error", path + ": cannot write: out of memory");
      all_written = false;
    }
  };
  write(spec.json_file, [&] { return trial_json(description, result, writing); });
  write(spec.csv_file, [&] { return trial_csv(result.trace); });
  write(spec.svg_file, [&] { return trial_svg(scene, result); });
  return all_written;
}

// --record: the trial as a teacher's recording, only when every stroke was written in order (a replay
// follows the teacher stroke by stroke). Returns whether it was written.
bool write_teacher_recording(const TrialSpec& spec, const TrialDescription& description,
                             const TrialResult& result) {
  if (spec.record_file.empty()) return true;
  if (result.aborted || !result.metrics.completed_in_order) {
    std::fprintf(
        stderr,
        "calligraphy trial: error: --record %s: not written: the trial did not complete every stroke "
        "in order (%zu of %zu strokes, %s), so it cannot teach them\n",
        spec.record_file.c_str(), result.metrics.strokes_completed, result.metrics.strokes_total,
        to_string(result.end));
    return false;
  }
  try {
    const TeacherRecording recording = teacher_recording_from_trace(
        description.characters, description.writer, description.device, description.rate_hz, result.trace);
    write_output(spec.record_file, teacher_recording_json(recording));
    return true;
  } catch (const Error& e) {
    print_error_line("calligraphy trial", "error", std::string("--record: ") + e.what());
  } catch (const std::bad_alloc&) {
    print_error_line("calligraphy trial", "error", spec.record_file + ": cannot write: out of memory");
  }
  return false;
}

int run_trial(const TrialCommand& command, const DeviceRegistry& devices) {
  require_one_standard_output(
      {{"--json", command.json == "-"}, {"--svg", command.svg == "-"}, {"--csv", command.csv == "-"}});
  std::optional<RecordedTrial> recorded;
  if (!command.spec_file.empty()) {
    recorded = recorded_from(command);
  } else if (command.app->count("CHARS") == 0) {
    throw UsageError("CHARS is required (or --spec RECORD)");
  }
  // Before any character is loaded.
  check_scene_size(characters_from(recorded ? recorded->spec.characters : command.characters, "CHARS").size(),
                   "CHARS");
  // Checked once, here; the runner and the renderer take it as it is.
  const Checked<TrialSpec> checked = recorded ? checked_spec(command, *recorded) : spec_from(command);
  const TrialSpec& spec = *checked;
  const std::u32string chars = characters_from(spec.characters, "CHARS");
  const DeviceListing device = find_cli_device(devices, "--device", spec.device);
  bool simulated = false;
  try {
    simulated = simulated_writer_writes(spec, simulated_writer_moves(device));
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  // A profile or its settings describe the simulated writer: with a person writing they would be ignored.
  if (!simulated && command.profile_option->count() > 0) {
    throw UsageError("--writer-profile applies to the simulated writer, not to a person (--writer person)");
  }
  if (!simulated && !spec.writer_parameters.empty()) {
    throw UsageError("--writer-param applies to the simulated writer, not to a person (--writer person)");
  }
  // The simulated writer, its profile and settings checked here (a record's writer as it wrote).
  const auto writing = [&] {
    try {
      return recorded ? std::make_unique<SimulatedWriting>(recorded->spec, recorded->writer)
                      : std::make_unique<SimulatedWriting>(spec);
    } catch (const InvalidArgument& e) {
      throw UsageError(e.what());
    }
  }();
  // Lock-step pacing has no wall clock, so no stall can be bounded: the option would be ignored.
  const bool real_time =
      spec.pacing == TrialPacing::real_time || (spec.pacing == TrialPacing::automatic && device.capabilities.hardware);
  if (command.watchdog_option->count() > 0 && !real_time) {
    throw UsageError(
        "--watchdog-ms applies to real-time pacing only (--pacing real-time, or a hardware device)");
  }
  // Every input and output is checked before the trial: no output replaces an input or another output.
  FilePlan files;
  files.input("--teacher", spec.teacher);
  files.input("--spec", command.spec_file);
  add_library_inputs(files, command.library);
  files.output("--json", spec.json_file);
  files.output("--csv", spec.csv_file);
  files.output("--svg", spec.svg_file);
  files.output("--record", spec.record_file);
  // From here a stop signal ends the trial at its next tick and the outputs are still written.
  const StopSignals stop_signals;
  const CharacterSource source(command.library);  // only these characters are read (on demand from a store)
  std::vector<Character> characters;
  std::map<char32_t, std::size_t> loaded;  // a character repeated in CHARS is read and fitted once
  for (char32_t c : chars) {
    const auto [at, added] = loaded.try_emplace(c, characters.size());
    characters.push_back(added ? source.load(c) : characters[at->second]);
  }
  const Scene scene = Scene::lay_out(characters, recorded ? recorded->layout : SceneLayout{});
  // A signal while the characters were read: nothing recorded yet, no device opened, no file written.
  if (const int signal = StopSignals::received()) {
    std::fprintf(stderr, "calligraphy trial: stopped by %s before the trial started; nothing written\n",
                 signal_name(signal));
    return exit_status_after(signal);
  }

  TrialRunInputs inputs;
  inputs.registry = &devices;
  inputs.should_stop = StopSignals::stop_requested();
  inputs.hand_maker = writing.get();
  TrialRun run;
  try {
    if (spec.guidance && spec.guidance_mode == GuidanceMode::replay) inputs.teacher = teacher_samples(spec);
    run = recorded ? rerun_trial(*recorded, checked, scene, inputs) : run_trial_spec(checked, scene, inputs);
  } catch (const InvalidArgument& e) {
    if (!recorded) throw;
    throw DataError("--spec " + command.spec_file + ": " + e.what());  // e.g. other character data
  }
  TrialResult& result = run.result;
  TrialDescription description = describe(spec, run, *writing, device);
  description.specification_json = recorded_trial_json(recorded_trial(spec, run, *writing, scene));
  const int signal = StopSignals::received();
  if (result.end == TrialEnd::interrupted && result.abort_reason.empty() && signal != 0) {
    result.abort_reason = std::string("stopped by ") + signal_name(signal);
  }
  // The recording first (it cannot be repeated), then the table. Outputs are written for a trial that
  // ended early too: they hold every tick recorded.
  const bool written = write_trial_outputs(spec, description, scene, result, run.metrics) &&
                       write_teacher_recording(spec, description, result);
  // Standard output carries one document: the table, or the output given as '-'.
  if (spec.json_file != "-" && spec.svg_file != "-" && spec.csv_file != "-")
    print_trial_table(description, scene, result, run.metrics);
  if (signal != 0) {
    std::fprintf(stderr, "calligraphy trial: stopped by %s after %.3f s (%s); %s\n", signal_name(signal),
                 result.metrics.time_s, to_string(result.end),
                 written ? "every recorded tick was written" : "an output could not be written");
    return written ? exit_status_after(signal) : 1;
  }
  if (!written) return 1;
  if (result.aborted) {
    print_error_line("calligraphy trial", "error",
                     std::string("the trial ended early (") + to_string(result.end) + ")" +
                         (result.abort_reason.empty() ? "" : ": " + result.abort_reason));
    return 1;
  }
  return 0;
}

// The specification's help of field `key`: for a guidance law's parameter, its table's doc, unit and range,
// the range the specification checks.
std::string spec_help(std::string_view key) {
  for (const TrialSpecField& field : trial_spec_fields()) {
    if (field.key == key) return std::string(field.help);
  }
  return {};
}

}  // namespace

void add_trial_command(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  auto command = std::make_shared<TrialCommand>();
  CLI::App* app = commands.add(root, "trial", "Run a guided writing trial of CHARS on a haptic device",
                               [command, &devices] { return run_trial(*command, devices); });
  command->app = app;
  add_positional(*app, "CHARS", command->characters, "the characters to write, left to right (UTF-8)")
      ->required(false);
  add_input_path(*app, "--spec", command->spec_file, "RECORD",
                 "run again the trial a record states (a trial --json file or a study trial record, its "
                 "\"specification\"): identical on the simulated device; CHARS and the trial's options then "
                 "come from it",
                 "none");
  add_text(*app, "--device", command->device, "NAME", "the device, by its name in `calligraphy devices`");
  add_choice(*app, "--guidance", command->guidance, {"on", "off"}, "guiding force towards the stroke");
  add_choice(
      *app, "--guidance-mode", command->guidance_mode, guidance_mode_choices(),
      "how the guidance acts: the paper's fixture, faded by --guidance-gain, replaying --teacher, only "
      "beyond --assist-band, pushing off the stroke (--amplification-gain), or pulling along it at "
      "--timing-speed");
  add_text(*app, "--guidance-gain", command->guidance_gain_text, "G", spec_help("guidance_gain"), "1");
  add_text(*app, "--assist-band", command->assist_band_text, "M", spec_help("assist_band_m"), "0.001");
  add_text(*app, "--amplification-gain", command->amplification_gain_text, "G",
           spec_help("amplification_gain"), "0.25");
  add_text(*app, "--timing-speed", command->timing_speed_text, "M/S", spec_help("timing_speed_m_s"), "0.04");
  add_input_path(*app, "--teacher", command->teacher, "FILE",
                 "replay: the teacher's recording of CHARS (made with --record)", "none");
  add_writer_option(*app, command->writer,
                    "who writes: the simulated writer (on the simulated and emulated devices it moves) or a "
                    "person (on a hardware device)",
                    "simulated on a simulated or emulated device, person on hardware");
  command->profile_option =
      add_choice(*app, "--writer-profile", command->writer_profile, {"novice", "skilled", "foreign"},
                 "the simulated writer's profile (docs/writer.md)");
  add_repeated_text(*app, "--writer-param", command->writer_parameters, "KEY=VALUE",
                    "set a field of the simulated writer's profile (repeatable; keys: docs/writer.md)");
  add_unsigned(*app, "--seed", command->seed, "N", "seed of the simulated writer (a 64-bit integer)");
  add_text(*app, "--rate", command->rate_text, "HZ",
           "servo rate [Hz], in [100, 100000] (real time: at most 10000)");
  add_text(*app, "--max-duration", command->max_duration_text, "S", "the trial ends after this much time [s]",
           "300");
  add_choice(*app, "--pacing", command->pacing, {"auto", "lock-step", "real-time"},
             "auto: lock-step for devices a simulated writer moves, real time for any other");
  add_choice(
      *app, "--realtime", command->realtime, {"enforce", "ignore"},
      "real-time pacing: fail unless SCHED_FIFO, CPU pinning and locked memory are obtained (enforce)");
  command->watchdog_option = add_integer(
      *app, "--watchdog-ms", command->watchdog_ms, "MS",
      "real-time pacing: end the trial when the device holds one force longer than this [ms]; 0: off", 0,
      60000);
  add_library_options(*app, command->library, true);
  add_output_path(*app, "--json", command->json, "write the metrics as JSON", StandardOutput::allowed);
  add_output_path(*app, "--svg", command->svg, "draw the reference and the pen trace as SVG",
                  StandardOutput::allowed);
  add_output_path(*app, "--csv", command->csv,
                  "write the trace (t,x,y,z,fx,fy,fz,state,stroke,element; s, m, N) as CSV",
                  StandardOutput::allowed);
  add_output_path(*app, "--record", command->record,
                  "write the trial as a teacher's recording for --guidance-mode replay (a trial that wrote "
                  "every stroke in order)",
                  StandardOutput::refused);
}

}  // namespace calligraphy::cli
