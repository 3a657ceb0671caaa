// `calligraphy trial CHARS ...`: a whole guided writing trial on any registered device (the simulated one
// by default), through run_trial: lock-step for devices a simulated writer moves, on the real-time
// ServoLoop otherwise or with --pacing real-time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/teacher_recording.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/sim/writer_profile.hpp"
#include "calligraphy/trial/trial.hpp"
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
  double guidance_gain = 1.0;
  const CLI::Option* gain_option = nullptr;
  std::string teacher;  // replay: the recording's path
  std::string record;   // write the trial as a teacher's recording
  std::uint64_t seed = 0;
  double rate_hz = TrialOptions{}.rate_hz;
  std::string pacing = "auto";
  std::string realtime = "ignore";
  std::int64_t watchdog_ms = std::llround(ServoLoopOptions{}.stall_timeout_s * 1000.0);
  const CLI::Option* watchdog_option = nullptr;  // given on the command line when its count() > 0
  LibraryOptions library;
  std::string json, svg, csv;
};

// The listing of `name`, or a UsageError (exit 2) naming every device that can be opened.
DeviceListing find_device(const std::string& name) {
  const DeviceSurvey survey = cli_device_registry().survey();
  const auto found = std::find_if(survey.devices.begin(), survey.devices.end(),
                                  [&](const DeviceListing& listing) { return listing.name == name; });
  if (found != survey.devices.end()) return *found;
  std::string names;
  for (const DeviceListing& listing : survey.devices) names += (names.empty() ? "" : ", ") + listing.name;
  throw UsageError("--device: unknown device '" + name +
                   "'; registered devices: " + (names.empty() ? "none" : names));
}

// The profile of --writer-profile with each --writer-param applied; a UsageError naming the setting and
// listing the known keys when one is refused.
WriterProfile writer_from(const TrialCommand& command) {
  WriterProfile profile = writer_profile(command.writer_profile);
  for (const std::string& setting : command.writer_parameters) {
    try {
      apply_writer_setting(profile, setting);
    } catch (const InvalidArgument& e) {
      std::string message = std::string("--writer-param '") + setting + "': " + e.what();
      if (message.find("known:") == std::string::npos) {
        std::string keys;
        for (const std::string& key : writer_parameter_names()) keys += (keys.empty() ? "" : ", ") + key;
        message += "; known keys: " + keys;
      }
      throw UsageError(message);
    }
  }
  return profile;
}

// The combinations of the guidance options that mean nothing are refused before anything runs.
void check_guidance_options(const TrialCommand& command) {
  if (command.guidance == "off" && command.guidance_mode != "fixed") {
    throw UsageError("--guidance-mode " + command.guidance_mode +
                     ": needs guidance on (it is given with --guidance off)");
  }
  if (command.gain_option->count() > 0 && command.guidance_mode != "fading") {
    throw UsageError("--guidance-gain applies to --guidance-mode fading only");
  }
  if (command.guidance_mode == "replay" && command.teacher.empty()) {
    throw UsageError("--teacher: required with --guidance-mode replay (a recording made with --record)");
  }
  if (!command.teacher.empty() && command.guidance_mode != "replay") {
    throw UsageError("--teacher applies to --guidance-mode replay only");
  }
}

// The teacher's recording of --teacher, checked against the characters to write (a DataError naming the
// file when it cannot be read, an InvalidArgument naming both character lists when they differ).
TeacherRecording teacher_for(const TrialCommand& command) {
  TeacherRecording teacher = read_teacher_recording(command.teacher);
  try {
    require_teacher_for(teacher, command.characters);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("--teacher " + command.teacher + ": " + e.what());
  }
  return teacher;
}

// A profile or its settings describe the simulated writer: with a person writing they would be ignored.
void check_writer_options(const TrialCommand& command, const std::string& writer) {
  if (writer != kPersonWriter) return;
  if (command.profile_option->count() > 0) {
    throw UsageError("--writer-profile applies to the simulated writer, not to a person (--writer person)");
  }
  if (!command.writer_parameters.empty()) {
    throw UsageError("--writer-param applies to the simulated writer, not to a person (--writer person)");
  }
}

// Every use of the trial runner's options and run_trial is here, in one place.
TrialResult run_trial_on_device(const TrialCommand& command, const DeviceListing& device,
                                const std::string& who_writes, const Scene& scene,
                                const WriterProfile& writer, const TeacherRecording* teacher,
                                TrialDescription& description) {
  TrialOptions options;
  options.force.guidance = command.guidance == "on";
  options.force.guidance_mode = *guidance_mode_from_string(command.guidance_mode);
  options.force.guidance_gain = command.guidance_gain;
  if (teacher) options.force.teacher_trajectory = teacher->samples;
  fit_default_stiffness(options.force, device.info);
  options.simulation.writer = writer;
  options.simulation.seed = command.seed;
  options.rate_hz = command.rate_hz;
  options.keep_trace = !command.svg.empty() || !command.csv.empty() || !command.record.empty();
  options.pacing = command.pacing == "lock-step"   ? TrialPacing::lock_step
                   : command.pacing == "real-time" ? TrialPacing::real_time
                                                   : TrialPacing::automatic;
  options.loop.realtime = command.realtime == "enforce" ? RealtimeMode::enforce : RealtimeMode::ignore;
  options.loop.stall_timeout_s = static_cast<double>(command.watchdog_ms) / 1000.0;
  options.should_stop = StopSignals::stop_requested();
  // The report calls a person "human" (trial_json); the simulated writer by its profile.
  const bool person = who_writes == kPersonWriter;
  description = TrialDescription{
      command.characters,      options.force.guidance, person ? "human" : command.writer_profile,
      options.simulation.seed, options.rate_hz,        device.name,
      device.info.model};
  description.guidance_mode = options.force.guidance_mode;
  description.guidance_gain = options.force.guidance_gain;
  if (teacher) {
    description.teacher_file = command.teacher;
    description.teacher_characters = teacher->characters;
  }
  if (!person) {
    description.writer_profile = writer.name;
    description.writer_parameters = command.writer_parameters;
  }
  return calligraphy::run_trial(device.name, scene, options);
}

// Writes each output given; one that fails is reported on stderr and does not keep the others from being
// written. Returns whether all were written.
bool write_trial_outputs(const TrialCommand& command, const TrialDescription& description, const Scene& scene,
                         const TrialResult& result) {
  bool all_written = true;
  const auto write = [&](const std::string& path, const auto& text) {
    if (path.empty()) return;
    try {
      write_output(path, text());
    } catch (const Error& e) {  // DataError naming the path and the reason
      std::fprintf(stderr, "calligraphy trial: error: %s\n", e.what());
      all_written = false;
    } catch (const std::bad_alloc&) {  // a trace too large to format in memory
      std::fprintf(stderr, "calligraphy trial: error: %s: cannot write: out of memory\n", path.c_str());
      all_written = false;
    }
  };
  write(command.json, [&] { return trial_json(description, result); });
  write(command.csv, [&] { return trial_csv(result.trace); });
  write(command.svg, [&] { return trial_svg(scene, result); });
  return all_written;
}

// --record: the trial as a teacher's recording, only when every stroke was written in order (a replay
// follows the teacher stroke by stroke). Returns whether it was written.
bool write_teacher_recording(const TrialCommand& command, const TrialDescription& description,
                             const TrialResult& result) {
  if (command.record.empty()) return true;
  if (result.aborted || !result.metrics.completed_in_order) {
    std::fprintf(
        stderr,
        "calligraphy trial: error: --record %s: not written: the trial did not complete every stroke "
        "in order (%zu of %zu strokes, %s), so it cannot teach them\n",
        command.record.c_str(), result.metrics.strokes_completed, result.metrics.strokes_total,
        to_string(result.end));
    return false;
  }
  try {
    const TeacherRecording recording = teacher_recording_from_trace(
        description.characters, description.writer, description.device, description.rate_hz, result.trace);
    write_output(command.record, teacher_recording_json(recording));
    return true;
  } catch (const Error& e) {
    std::fprintf(stderr, "calligraphy trial: error: --record: %s\n", e.what());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "calligraphy trial: error: %s: cannot write: out of memory\n",
                 command.record.c_str());
  }
  return false;
}

int run_trial(const TrialCommand& command) {
  require_one_standard_output(
      {{"--json", command.json == "-"}, {"--svg", command.svg == "-"}, {"--csv", command.csv == "-"}});
  const std::u32string chars = characters_from(command.characters, "CHARS");
  check_scene_size(chars.size(), "CHARS");  // before any is loaded
  const DeviceListing device = find_device(command.device);
  const std::string who_writes = writer_for_device(command.writer, device);
  check_writer_options(command, who_writes);
  // Lock-step pacing has no wall clock, so no stall can be bounded: the option would be ignored.
  const bool real_time = command.pacing == "real-time" || (command.pacing == "auto" && device.hardware);
  if (command.watchdog_option->count() > 0 && !real_time) {
    throw UsageError(
        "--watchdog-ms applies to real-time pacing only (--pacing real-time, or a hardware device)");
  }
  check_guidance_options(command);
  // Every input and output is checked before the trial: no output replaces an input or another output.
  FilePlan files;
  files.input("--teacher", command.teacher);
  add_library_inputs(files, command.library);
  files.output("--json", command.json);
  files.output("--csv", command.csv);
  files.output("--svg", command.svg);
  files.output("--record", command.record);
  const WriterProfile writer = writer_from(command);
  std::unique_ptr<TeacherRecording> teacher;
  if (!command.teacher.empty()) teacher = std::make_unique<TeacherRecording>(teacher_for(command));
  // From here a stop signal ends the trial at its next tick and the outputs are still written.
  const StopSignals stop_signals;
  const CharacterSource source(command.library);  // only these characters are read (on demand from a store)
  std::vector<Character> characters;
  std::map<char32_t, std::size_t> loaded;  // a character repeated in CHARS is read and fitted once
  for (char32_t c : chars) {
    const auto [at, added] = loaded.try_emplace(c, characters.size());
    characters.push_back(added ? source.load(c) : characters[at->second]);
  }
  const Scene scene = Scene::lay_out(characters);
  // A signal while the characters were read: nothing recorded yet, no device opened, no file written.
  if (const int signal = StopSignals::received()) {
    std::fprintf(stderr, "calligraphy trial: stopped by %s before the trial started; nothing written\n",
                 signal_name(signal));
    return exit_status_after(signal);
  }

  TrialDescription description;
  TrialResult result =
      run_trial_on_device(command, device, who_writes, scene, writer, teacher.get(), description);
  const int signal = StopSignals::received();
  if (result.end == TrialEnd::interrupted && result.abort_reason.empty() && signal != 0) {
    result.abort_reason = std::string("stopped by ") + signal_name(signal);
  }
  // The recording first (it cannot be repeated), then the table. Outputs are written for a trial that
  // ended early too: they hold every tick recorded.
  const bool written = write_trial_outputs(command, description, scene, result) &&
                       write_teacher_recording(command, description, result);
  // Standard output carries one document: the table, or the output given as '-'.
  if (command.json != "-" && command.svg != "-" && command.csv != "-")
    print_trial_table(description, scene, result);
  if (signal != 0) {
    std::fprintf(stderr, "calligraphy trial: stopped by %s after %.3f s (%s); %s\n", signal_name(signal),
                 result.metrics.time_s, to_string(result.end),
                 written ? "every recorded tick was written" : "an output could not be written");
    return written ? exit_status_after(signal) : 1;
  }
  if (!written) return 1;
  if (result.aborted) {
    std::fprintf(stderr, "calligraphy trial: error: the trial ended early (%s)%s%s\n", to_string(result.end),
                 result.abort_reason.empty() ? "" : ": ", result.abort_reason.c_str());
    return 1;
  }
  return 0;
}

}  // namespace

void add_trial_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<TrialCommand>();
  CLI::App* app = commands.add(root, "trial", "Run a guided writing trial of CHARS on a haptic device",
                               [command] { return run_trial(*command); });
  add_positional(*app, "CHARS", command->characters, "the characters to write, left to right (UTF-8)");
  add_text(*app, "--device", command->device, "NAME", "the device, by its name in `calligraphy devices`");
  add_choice(*app, "--guidance", command->guidance, {"on", "off"}, "guiding force towards the stroke");
  add_choice(
      *app, "--guidance-mode", command->guidance_mode, {"fixed", "fading", "replay"},
      "how the guidance attracts: the paper's fixture, faded by --guidance-gain, or replaying --teacher");
  command->gain_option =
      add_number(*app, "--guidance-gain", command->guidance_gain, "G", "fading: gain on the guiding force",
                 "a number in [0, 1]", [](double gain) { return gain >= 0.0 && gain <= 1.0; });
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
  add_number(*app, "--rate", command->rate_hz, "HZ", "servo rate [Hz]", "a number of Hz in [100, 100000]",
             [](double hz) { return hz >= 100.0 && hz <= 100000.0; });
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
