// `calligraphy train CHARS ...`: the trainer window (src/trainer, docs/trainer.md): a live guided trial in
// real time, drawn at the display rate, with the mouse, a simulated hand on the mouse, a simulated writer
// or a haptic device. Built only with CALLIGRAPHY_BUILD_TRAINER; otherwise the command says so.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/writer_options.hpp"
#ifdef CALLIGRAPHY_WITH_TRAINER
#include "trainer/trainer.hpp"
#endif

namespace calligraphy::cli {
namespace {

struct TrainCommand {
  std::string characters;
  std::string device;  // empty: mouse-hand, or simulated with --writer simulated
  std::string writer = "person";
  std::string guidance = "on";
  std::string guidance_mode = "fixed";
  double guidance_gain = 1.0;
  std::string teacher;
  std::string record;
  std::uint64_t seed = 0;
  LibraryOptions library;
  std::string session;
  std::string subject = "anonymous";
  std::string window = "1280x800";
  std::string screenshot;
  double exit_after_s = 0.0;
  std::int64_t watchdog_ms = 0;
  const CLI::Option* watchdog_option = nullptr;       // given on the command line when its count() > 0
  const CLI::Option* guidance_gain_option = nullptr;  // given on the command line when its count() > 0
  bool quiz = false;
  bool engineer = false;
  bool no_demo = false;
  // The stroke acceptance's counts (StrokeAcceptance, their one definition: default and range).
  std::int64_t hint_after = static_cast<std::int64_t>(StrokeAcceptance{}.hint_after_misses);
  std::int64_t assist_after = static_cast<std::int64_t>(StrokeAcceptance{}.assist_after_misses);
  std::string quiz_screenshots;
};

// The files of the command, checked before anything opens (and in a build without the window too): the
// inputs, the outputs (none the same file as another or as an input), the folders written in.
void check_train_files(const TrainCommand& command) {
  if (!command.quiz && !command.quiz_screenshots.empty())
    throw UsageError("--quiz-screenshots: only with --quiz");
  FilePlan files;
  files.input("--teacher", command.teacher);
  add_library_inputs(files, command.library);
  files.output_folder("--session", command.session);
  files.output("--record", command.record);
  files.output("--screenshot", command.screenshot);
  files.existing_output_folder("--quiz-screenshots", command.quiz_screenshots);
}

// "WxH" in pixels, each in [min, 8192].
std::pair<int, int> window_size(const std::string& text) {
  const auto x = text.find('x');
  const auto number = [&](const std::string& part, int minimum) {
    if (part.empty() || part.size() > 5 || !std::all_of(part.begin(), part.end(), ::isdigit)) return -1;
    const int value = std::stoi(part);
    return value >= minimum && value <= 8192 ? value : -1;
  };
  const int width = x == std::string::npos ? -1 : number(text.substr(0, x), 800);
  const int height = x == std::string::npos ? -1 : number(text.substr(x + 1), 480);
  if (width < 0 || height < 0) {
    throw UsageError("--window: '" + text +
                     "' is not WIDTHxHEIGHT in pixels (width 800-8192, height 480-8192)");
  }
  return {width, height};
}

// Every usage and file check of the command, before anything opens, in a build without the window too:
// wrong options are reported as such (exit 2) wherever the command exists.
void check_train_options(const TrainCommand& command) {
  // Combinations of options before any file is read: a quiz has no guidance, so nothing that sets one.
  if (command.quiz) {
    std::string guidance_set;  // the first option given that sets guidance
    if (command.guidance_mode != "fixed") {
      guidance_set.append("--guidance-mode ").append(command.guidance_mode);
    } else if (!command.teacher.empty()) {
      guidance_set.append("--teacher ").append(command.teacher);
    } else if (command.guidance_gain_option->count() > 0) {
      guidance_set.append("--guidance-gain");
    }
    if (!guidance_set.empty()) {
      std::string message = "--quiz: a quiz has no guidance; drop ";
      throw UsageError(message.append(guidance_set));
    }
  }
  if (guidance_mode_from_string(command.guidance_mode) == GuidanceMode::replay && command.teacher.empty())
    throw UsageError("--guidance-mode replay: needs --teacher FILE (a recording made with --record)");
  if (!is_subject_id(command.subject)) {
    throw UsageError("--subject: '" + command.subject +
                     "' must be 1-64 characters of A-Z a-z 0-9 _ - (it names the session folder)");
  }
  window_size(command.window);
  check_train_files(command);
}

#ifdef CALLIGRAPHY_WITH_TRAINER
int run_train(const TrainCommand& command, DeviceRegistry& devices) {
  check_train_options(command);
  trainer::register_trainer_devices(devices);
  const std::u32string chars = characters_from(command.characters, "CHARS");
  trainer::TrainerOptions options;
  const bool simulated_writer = command.writer == kSimulatedWriter;
  options.device = !command.device.empty() ? command.device : simulated_writer ? "simulated" : "mouse-hand";
  options.registry = &devices;  // the command line's devices, the mouse ones included
  // A simulated writer moves only a device with a hand port; a person moves any other.
  options.simulated_writer =
      writer_for_device(command.writer, find_cli_device(devices, "--device", options.device)) ==
      TrialWriter::simulated;
  options.guidance = command.guidance == "on";
  options.quiz = command.quiz;
  options.engineer = command.engineer;
  options.demonstrate = !command.no_demo;
  // Every trial's and the quiz's acceptance: the hint and the assisted credit after these misses.
  options.acceptance.hint_after_misses = static_cast<double>(command.hint_after);
  options.acceptance.assist_after_misses = static_cast<double>(command.assist_after);
  options.quiz_screenshots = command.quiz_screenshots;
  options.guidance_mode = *guidance_mode_from_string(command.guidance_mode);
  options.guidance_gain = command.guidance_gain;
  options.record = command.record;
  if (!command.teacher.empty()) {
    const TeacherRecording teacher = read_teacher_recording(command.teacher);
    try {
      require_teacher_for(teacher, command.characters);
    } catch (const InvalidArgument& e) {
      throw UsageError(std::string("--teacher: ") + e.what() +
                       " (a trial is one character: practise that one character alone)");
    }
    options.teacher = teacher.samples;
  }
  options.seed = command.seed;
  options.session_dir = command.session;
  options.subject = command.subject;
  std::tie(options.width_px, options.height_px) = window_size(command.window);
  options.screenshot = command.screenshot;
  options.exit_after_s = command.exit_after_s;
  if (command.watchdog_option->count() > 0)
    options.watchdog_s = static_cast<double>(command.watchdog_ms) / 1000.0;
  options.library_version = CALLIGRAPHY_VERSION;
  const CharacterSource source(command.library);
  for (const char32_t c : chars) {
    trainer::TrainerCharacter character;
    character.model = source.load_named(c, "CHARS");
    character.utf8 = encode_utf8(c);
    try {
      character.outlines = source.load_outlines(c);
    } catch (const DataError& e) {  // e.g. a store built with `--outlines off`: drawn without outlines
      print_error_line("calligraphy train", "warning",
                       "no stroke outlines for " + character.utf8 + ": " + e.what());
    }
    options.characters.push_back(std::move(character));
  }
  return trainer::run_trainer(options);
}
#else
int run_train(const TrainCommand& command, DeviceRegistry&) {
  check_train_options(command);
  throw Error(
      "this calligraphy was built without the trainer window (CALLIGRAPHY_BUILD_TRAINER=OFF; it needs GLFW 3 "
      "and Dear ImGui: libglfw3-dev libimgui-dev)");
}
#endif

}  // namespace

void add_train_command(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  auto command = std::make_shared<TrainCommand>();
  CLI::App* app = commands.add(root, "train", "Practise CHARS in a window: a live guided trial in real time",
                               [command, &devices] { return run_train(*command, devices); });
  add_positional(*app, "CHARS", command->characters, "the characters to practise, left to right (UTF-8)");
  add_text(*app, "--device", command->device, "NAME",
           "the device: mouse, mouse-hand (docs/devices.md), a haptic device, or simulated with --writer "
           "simulated",
           "mouse-hand; simulated with --writer simulated");
  add_writer_option(
      *app, command->writer,
      "who writes: a person, or the simulated writer live on the simulated device (a demonstration)",
      "person");
  add_choice(*app, "--guidance", command->guidance, {"on", "off"},
             "guiding force towards the stroke (G toggles)");
  add_choice(*app, "--guidance-mode", command->guidance_mode, enum_choices<GuidanceMode>(),
             "how guidance acts (docs/force-rendering.md): the paper's fixed fixture, faded trial by trial "
             "from the mean deviation, along a teacher's recording, only beyond a band that adapts trial by "
             "trial, a gentle push off the stroke, or a target pacing the stroke (M cycles it)");
  command->guidance_gain_option =
      add_number(*app, "--guidance-gain", command->guidance_gain, "G",
                 "fading: the first trial's gain, faded after each trial, in [0, 1]", "a number in [0, 1]",
                 [](double g) { return g >= 0.0 && g <= 1.0; });
  add_input_path(*app, "--teacher", command->teacher, "FILE",
                 "replay: the teacher's recording (JSON, from --record)", "none");
  add_output_path(*app, "--record", command->record,
                  "write each completed trial here as a teacher's recording (JSON), replacing the last",
                  StandardOutput::refused);
  add_unsigned(*app, "--seed", command->seed, "N", "seed of the simulated writer");
  add_library_options(*app, command->library, true);
  add_output_folder(
      *app, "--session", command->session,
      "save the trials as they end into a session folder DIR/SUBJECT/train-TIME/ (docs/experiments.md)",
      "not saved");
  add_text(*app, "--subject", command->subject, "ID",
           "the subject's id in the saved trials (A-Z a-z 0-9 _ -)");
  add_text(*app, "--window", command->window, "WxH", "window size [px]");
  add_output_path(*app, "--screenshot", command->screenshot,
                  "write the window as PNG after the last character's trial, or at exit",
                  StandardOutput::refused);
  add_flag(*app, "--quiz", command->quiz,
           "a quiz (docs/trainer.md): no guidance; each stroke is judged as the pen lifts, "
           "accepted or missed by the stroke matcher the renderer uses (docs/stroke-acceptance.md)");
  const ParameterRange hint_range = parameter_field(&StrokeAcceptance::hint_after_misses).range;
  add_integer(*app, "--hint-after-misses", command->hint_after, "N",
              "show the expected stroke after N misses on it, and after each further miss; 0: never (the "
              "stroke acceptance's hint_after_misses, as `trial --hint-after-misses`)",
              static_cast<std::int64_t>(hint_range.low), static_cast<std::int64_t>(hint_range.high));
  const ParameterRange assist_range = parameter_field(&StrokeAcceptance::assist_after_misses).range;
  add_integer(
      *app, "--assist-after-misses", command->assist_after, "N",
      "after N misses on a stroke, demonstrate it and credit it as assisted, so the trial goes on; 0: "
      "never (the stroke acceptance's assist_after_misses, as `trial --assist-after-misses`)",
      static_cast<std::int64_t>(assist_range.low), static_cast<std::int64_t>(assist_range.high));
  add_output_folder(*app, "--quiz-screenshots", command->quiz_screenshots,
                    "quiz: write the window as DIR/quiz-NN-VERDICT.png on the first frame after each judged "
                    "stroke (an existing folder)",
                    "not written");
  add_flag(*app, "--engineer", command->engineer,
           "the engineer's panel (docs/trainer.md): interaction state, ticks, elements, pen and force, the "
           "per-stroke table; without it the learner's view");
  add_flag(*app, "--no-demo", command->no_demo,
           "start writing at once: no stroke-order demonstration before each character's first trial (D "
           "still demonstrates)");
  add_number(
      *app, "--exit-after", command->exit_after_s, "SECONDS",
      "unattended: quit after this long [s, (0, 86400]], or once every character had its trial",
      "a number of seconds in (0, 86400]", [](double s) { return s > 0.0 && s <= 86400.0; }, "none");
  command->watchdog_option = add_integer(
      *app, "--watchdog-ms", command->watchdog_ms, "MS",
      "end the trial when the device holds one force longer than this [ms]; 0: off (mouse, mouse-hand and "
      "simulated hold no force against a hand)",
      0, 60000, "50 on a haptic device, 0 on mouse, mouse-hand and simulated");
}

}  // namespace calligraphy::cli
