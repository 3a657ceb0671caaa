// `calligraphy trial CHARS ...`: a whole guided writing trial on any registered device (the simulated one
// by default). The options are the trial specification's (trial_spec.hpp), parsed and validated by it, and
// the trial is run by its one runner (run_trial_spec, which builds the whole trial; rerun_trial for --spec):
// lock-step for devices a simulated writer moves, on the real-time ServoLoop otherwise or with --pacing
// real-time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/rerun_check.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "calligraphy/trial/trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/signals.hpp"
#include "cli/writer_options.hpp"

namespace calligraphy::cli {
namespace {

struct TrialCommand {
  // The options made from the specification's schema set their field here, each parsed once by the
  // schema's parser; the others are this command's own (who writes, the profile, the settings, --spec).
  TrialSpec spec;
  std::string writer;  // person or simulated; empty: the device's own (writer_for_device)
  std::string writer_profile = TrialSpec{}.writer_profile;
  std::vector<std::string> writer_parameters;  // "key=value", applied in turn
  LibraryOptions library;
  std::string spec_file;          // --spec: a trial record (or its specification) to run again
  bool check = false;             // --check: validate the trial as stated, run nothing, write nothing
  const CLI::App* app = nullptr;  // to ask which options were given
};

// The options taken from --spec's record with it: every option of the specification but its outputs and a
// replay's --teacher.
bool stated_by_record(std::string_view option) {
  return option.starts_with("--") && option != "--json" && option != "--csv" && option != "--svg" &&
         option != "--teacher";
}

// --spec: the record's specification, with this command's outputs (and a replay's --teacher when given).
RecordedTrial recorded_from(const TrialCommand& command) {
  if (command.app->count("CHARS") > 0) {
    throw UsageError("CHARS: the characters come from --spec " + command.spec_file +
                     "; give one or the other");
  }
  for (const SchemaField& field : SchemaOf<TrialSpec>::get().fields) {
    const std::string option(field.option);
    if (stated_by_record(option) && command.app->count(option) > 0) {
      throw UsageError(option + ": the trial is stated by --spec " + command.spec_file +
                       "; with it go only --json, --csv, --svg, --teacher and the character data options");
    }
  }
  RecordedTrial recorded = read_study_recorded_trial(command.spec_file);
  for (const std::string& pointer : recorded.defaulted) {
    print_error_line("calligraphy trial", "note",
                     "--spec " + command.spec_file + ": " + pointer +
                         " is not in this earlier version of the record; it takes its default");
  }
  // The fields the record's version fixes run as that version ran: said with the value taken, and a value
  // the record gives in their place is said to be left unused.
  for (const RecordedTrial::VersionRule& rule : recorded.version_rules) {
    const std::string taken = shortest_decimal(rule.taken);
    const std::string as_ran = "records of version " + std::to_string(rule.version) + " ran with " + taken;
    print_error_line("calligraphy trial", "note",
                     "--spec " + command.spec_file + ": " + rule.pointer +
                         (rule.given ? " is " + shortest_decimal(*rule.given) + " in the record, but " +
                                           as_ran + "; it takes " + taken
                                     : " is not in this earlier version of the record; it takes " + taken +
                                           ", as " + as_ran));
  }
  if (!command.spec.teacher.empty()) {
    if (recorded.spec.guidance_mode != GuidanceMode::replay) {
      throw UsageError("--teacher: the trial in --spec " + command.spec_file +
                       " is not a replay (guidance mode " + to_string(recorded.spec.guidance_mode) + ")");
    }
    recorded.spec.teacher = command.spec.teacher;
  }
  recorded.spec.json_file = command.spec.json_file;
  recorded.spec.csv_file = command.spec.csv_file;
  recorded.spec.svg_file = command.spec.svg_file;
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

// The trial specification of the command line: the schema's options set their fields as they were parsed;
// the writer's options are added through the specification's parser; one check, an error there a usage error
// naming the option.
Checked<TrialSpec> spec_from(const TrialCommand& command) {
  TrialSpec spec = command.spec;
  try {
    if (!command.writer.empty()) set_trial_spec_field(spec, "writer", command.writer);
    if (command.app->count("--writer-profile") > 0) spec.writer_profile = command.writer_profile;
    for (const std::string& setting : command.writer_parameters)
      set_trial_spec_field(spec, "--writer-param", setting);
    // An option given for a guidance setting the trial does not have is refused at its default value too.
    std::vector<std::string> given;
    for (const SchemaField& field : SchemaOf<TrialSpec>::get().fields) {
      if (!field.option.empty() && command.app->count(std::string(field.option)) > 0)
        given.emplace_back(field.name);
    }
    refuse_inapplicable_fields(spec, given);
    return Checked<TrialSpec>::check(std::move(spec));
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
}

// What the trial's JSON and table say of it: the specification and the device it ran on.
TrialDescription describe(const TrialSpec& spec, const TrialRun& run, const SimulatedWriting& writing,
                          const DeviceListing& device) {
  // Who wrote it, spelt as the specification's `writer`; the simulated writer's profile beside it.
  TrialDescription description{
      spec.characters,  spec.guidance, run.simulated_writer ? kSimulatedWriter : kPersonWriter,
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

// A replay's teacher: the recording --teacher (or the record) names, of these characters and, for a record
// that names its teacher's SHA-256, that recording; `sha256` is set to its file's.
std::vector<TeacherSample> teacher_samples(const TrialCommand& command, const TrialSpec& spec,
                                           const std::optional<RecordedTrial>& recorded,
                                           std::string& sha256) {
  TeacherFile teacher =
      recorded && command.spec.teacher.empty()
          ? read_record_named_teacher(*recorded, "--spec " + command.spec_file, "--teacher FILE")
          : read_recorded_teacher(recorded ? *recorded : RecordedTrial{}, spec.teacher);
  try {
    require_teacher_for(teacher.recording, spec.characters);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("teacher (--teacher) " + spec.teacher + ": " + e.what());
  }
  sha256 = std::move(teacher.sha256);
  return std::move(teacher.recording.samples);
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
        description.characters,
        description.writer_profile.empty() ? kPersonWriter : description.writer_profile, description.device,
        description.rate_hz, result.trace);
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
  require_one_standard_output({{"--json", command.spec.json_file == "-"},
                               {"--svg", command.spec.svg_file == "-"},
                               {"--csv", command.spec.csv_file == "-"}});
  std::optional<RecordedTrial> recorded;
  if (!command.spec_file.empty()) {
    recorded = recorded_from(command);
  } else if (command.app->count("CHARS") == 0) {
    throw UsageError("CHARS is required (or --spec RECORD)");
  }
  // Before any character is loaded.
  check_scene_size(
      characters_from(recorded ? recorded->spec.characters : command.spec.characters, "CHARS").size(),
      "CHARS");
  // Checked once, here; the runner and the renderer take it as it is.
  const Checked<TrialSpec> checked = recorded ? checked_spec(command, *recorded) : spec_from(command);
  const TrialSpec& spec = *checked;
  const std::u32string chars = characters_from(spec.characters, "CHARS");
  // Who writes and how the ticks are paced are checked against the kind of device (simulated writer or
  // person), which is known whether or not the device can be used now: a pairing the device cannot have is
  // a usage error (a record's: at its JSON pointer, exit 2) before a device that cannot be used (exit 1).
  const auto writer_on = [&](bool simulated_hand) {
    bool simulated_writer = false;
    try {
      simulated_writer = simulated_writer_writes(spec, simulated_hand);
    } catch (const InvalidArgument& e) {
      if (recorded) throw InputError(command.spec_file + ": /specification/trial/writer: " + e.what());
      throw UsageError(e.what());
    }
    if (spec.pacing == TrialPacing::lock_step && !simulated_hand) {
      const std::string reason = "lock-step needs a device the simulated writer moves; '" + spec.device +
                                 "' is moved by a person, in real time";
      if (recorded) throw InputError(command.spec_file + ": /specification/trial/pacing: " + reason);
      throw UsageError("--pacing lock-step: " + reason + " (--pacing real-time or auto)");
    }
    // A profile or its settings describe the simulated writer: with a person writing they would be ignored.
    if (!simulated_writer && command.app->count("--writer-profile") > 0) {
      throw UsageError("--writer-profile applies to the simulated writer, not to a person (--writer person)");
    }
    if (!simulated_writer && !spec.writer_parameters.empty()) {
      throw UsageError("--writer-param applies to the simulated writer, not to a person (--writer person)");
    }
    return simulated_writer;
  };
  // --check needs only the kind of device, not the device: a trial stated for a device that cannot be used
  // now (not plugged in on this computer) is still a valid statement.
  bool simulated_hand = false;
  const std::optional<DeviceListing> device = [&]() -> std::optional<DeviceListing> {
    try {
      DeviceListing found = find_cli_device(devices, recorded ? "" : "--device", spec.device);
      simulated_hand = simulated_writer_moves(found);
      return found;
    } catch (const DeviceUnavailable&) {
      const std::optional<bool> kind = kind_moved_by_simulated_hand(devices, spec.device);
      if (!kind) throw;
      writer_on(*kind);
      if (!command.check) throw;
      simulated_hand = *kind;
      return std::nullopt;
    } catch (const UsageError& e) {
      // A record's device is named as every bad value of it is (exit 2).
      if (recorded) throw InputError(command.spec_file + ": /specification/trial/device: " + e.what());
      throw;
    }
  }();
  (void)writer_on(simulated_hand);
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
  // A device of a person's kind is hardware, paced in real time (docs/cli.md, "trial": --pacing auto).
  const bool hardware = device ? device->capabilities.hardware : !simulated_hand;
  const bool real_time =
      spec.pacing == TrialPacing::real_time || (spec.pacing == TrialPacing::automatic && hardware);
  if (command.app->count("--watchdog-ms") > 0 && !real_time) {
    throw UsageError(
        "--watchdog-ms applies to real-time pacing only (--pacing real-time, or a hardware device)");
  }
  // --check: everything a trial's statement is checked for is checked above; no character is read, no
  // device opened, no file written.
  if (command.check) {
    std::printf("%s: a valid trial specification\n", recorded ? command.spec_file.c_str() : "the options");
    return 0;
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
    if (!added) {
      characters.push_back(characters[at->second]);
    } else if (!recorded) {
      characters.push_back(source.load_named(c, "CHARS"));
    } else {
      try {  // a record's character the library lacks is named as every bad value of it is (exit 2)
        characters.push_back(source.load(c));
      } catch (const CharacterNotFound& e) {
        throw InputError(command.spec_file + ": /specification/trial/characters: " + e.what());
      }
    }
  }
  const Scene scene = Scene::lay_out(characters, recorded ? recorded->layout : SceneLayout{});
  // A record written before its SHA-256 of the characters covered their medians, along which progress is
  // measured, matches the same models with medians or without: said, as it cannot tell which it was made on.
  if (recorded && recorded->scene_sha256 != scene_sha256(scene) &&
      recorded->scene_sha256 == scene_models_sha256(scene)) {
    print_error_line("calligraphy trial", "note",
                     "--spec " + command.spec_file +
                         ": the record's SHA-256 of the characters was written before it covered their "
                         "medians, so it cannot tell whether it was made on characters with medians or on "
                         "a store of the models only (corpus build --medians off); it runs here on the "
                         "characters read, another trace if it was made on the other kind");
  }
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
  std::string teacher_sha256;
  try {
    if (spec.guidance && spec.guidance_mode == GuidanceMode::replay)
      inputs.teacher = teacher_samples(command, spec, recorded, teacher_sha256);
    run = recorded ? rerun_trial(*recorded, checked, scene, inputs) : run_trial_spec(checked, scene, inputs);
  } catch (const InvalidArgument& e) {
    if (!recorded) throw;
    throw DataError("--spec " + command.spec_file + ": " + e.what());  // e.g. other character data
  }
  TrialResult& result = run.result;
  // A record changed since it was written runs as another trial: never silently.
  if (recorded) {
    if (const std::vector<std::string> differences = rerun_differences(*recorded, result);
        !differences.empty())
      print_error_line("calligraphy trial", "warning",
                       "--spec " + command.spec_file + ": " + rerun_differences_text(*recorded, differences));
  }
  TrialDescription description = describe(spec, run, *writing, *device);
  // The replay's teacher, bound to the record by the SHA-256 of the file read.
  const RecordedTrial ran = recorded_trial(spec, run, *writing, scene, teacher_sha256);
  description.specification_json = recorded_trial_json(ran);
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

// The specification's help of field `key` (its schema's doc, unit and range).
std::string spec_help(std::string_view key) { return SchemaOf<TrialSpec>::get().field(key)->description(); }

}  // namespace

void add_trial_command(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  auto command = std::make_shared<TrialCommand>();
  CLI::App* app = commands.add(root, "trial", "Run a guided writing trial of CHARS on a haptic device",
                               [command, &devices] { return run_trial(*command, devices); });
  command->app = app;
  add_positional(*app, "CHARS", command->spec.characters, spec_help("characters"))->required(false);
  add_input_path(*app, "--spec", command->spec_file, "RECORD",
                 "run again the trial a record states (a trial --json file or a study trial record, its "
                 "\"specification\"): identical on the simulated device; CHARS and the trial's options then "
                 "come from it",
                 "none");
  add_flag(*app, "--check", command->check,
           "check the trial as stated (--spec RECORD, or CHARS and the options) and exit: 0 when it is "
           "valid, as a trial would refuse it otherwise; no character is read, no device opened, nothing "
           "written");
  // Every field of the specification with an option of its own, typed, its unit, range and default from
  // the schema; files, who writes and the writer's profile and settings are declared below.
  const TrialSpec defaults;
  for (const SchemaField& field : SchemaOf<TrialSpec>::get().fields) {
    const std::string_view option = field.option;
    const bool own_declaration = field.kind == FieldKind::object_list || option == "--writer" ||
                                 (field.kind == FieldKind::string && option != "--device");
    if (!option.starts_with("--") || own_declaration) continue;
    add_schema_option(*app, field, &command->spec, &defaults);
  }
  add_input_path(*app, "--teacher", command->spec.teacher, "FILE", spec_help("teacher"), "none");
  add_writer_option(*app, command->writer, spec_help("writer"),
                    "simulated on a simulated or emulated device, person on hardware", true);
  add_choice(*app, "--writer-profile", command->writer_profile, name_choices(writer_profile_names()),
             spec_help("writer_profile"));
  add_repeated_text(*app, "--writer-param", command->writer_parameters, "KEY=VALUE",
                    spec_help("writer_parameters") + " (repeatable)");
  add_library_options(*app, command->library, true);
  add_output_path(*app, "--json", command->spec.json_file, spec_help("json_file"), StandardOutput::allowed);
  add_output_path(*app, "--svg", command->spec.svg_file, spec_help("svg_file"), StandardOutput::allowed);
  add_output_path(*app, "--csv", command->spec.csv_file, spec_help("csv_file"), StandardOutput::allowed);
  add_output_path(*app, "--record", command->spec.record_file, spec_help("record_file"),
                  StandardOutput::refused);
}

}  // namespace calligraphy::cli
