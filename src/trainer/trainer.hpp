#pragma once
// `calligraphy train`: a window (GLFW 3, OpenGL 3.3 core, Dear ImGui) showing a live guided trial, the
// servo loop on its own thread. See docs/trainer.md.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/stroke_outline.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_runner.hpp"

namespace calligraphy::trainer {

/// One character to practise: its model (the haptic reference) and its outlines (for drawing).
struct TrainerCharacter {
  Character model;
  CharacterOutlines outlines;
  std::string utf8;
  /// Whether it is drawn with its outline: a character from the bundled store has none (only its line).
  [[nodiscard]] bool outlined() const noexcept { return !outlines.strokes.empty(); }
};

struct TrainerOptions {
  std::vector<TrainerCharacter> characters;  ///< the row, practised left to right
  std::string device = "mouse-hand";         ///< a name in `registry`
  /// Where `device` is created (not owned; outlives the run): the program's registry, with the trainer's
  /// pointer devices added (`register_trainer_devices`). Required.
  const DeviceRegistry* registry = nullptr;
  bool simulated_writer = false;          ///< the simulated writer writes (device with a hand port)
  std::string writer_profile = "novice";  ///< novice or skilled
  std::uint64_t seed = 0;
  bool guidance = true;
  GuidanceMode guidance_mode = GuidanceMode::fixed;  ///< how guidance attracts (M cycles it)
  double guidance_gain = 1.0;          ///< the fading mode's first gain in [0, 1]; faded after each trial
  std::vector<TeacherSample> teacher;  ///< replay: the teacher's pen (one character, its recording)
  /// A quiz (analysis/quiz.hpp): guidance off, each stroke judged live by the stroke matcher as the pen
  /// lifts.
  bool quiz = false;
  /// Hint after N misses, backwards accepted or not. The trainer sets the acceptance and start radius to its
  /// trials' (the renderer's tolerances and the scene's start neighbourhood), so that quiz and renderer
  /// agree.
  QuizOptions quiz_options;
  /// When a stroke counts as written, and the misses after which it is hinted and credited assisted: every
  /// trial's (its specification's, TrialSpec::acceptance) and the quiz's.
  StrokeAcceptance acceptance;
  std::string quiz_screenshots;  ///< non-empty: a folder where a PNG is written after each judged stroke
  std::string record;            ///< non-empty: each completed trial is written here as a teacher recording
  std::string session_dir;       ///< empty: trials are not saved
  std::string subject = "anonymous";
  int width_px = 1280;
  int height_px = 800;
  /// Attended: each character's stroke order is demonstrated before its first trial (not in a quiz nor with
  /// the simulated writer); D demonstrates it again in any case.
  bool demonstrate = true;
  /// The engineer's panel: interaction state, ticks, elements, forces, the per-stroke table; else the
  /// learner's (docs/trainer.md).
  bool engineer = false;
  std::string screenshot;     ///< PNG written after the last character's trial, or at exit
  double exit_after_s = 0.0;  ///< > 0: unattended; quit after this long or once every character had its trial
  /// The servo loop's stall bound [s] in [0, 60] (ServoLoopOptions::stall_timeout_s; 0: off). Unset: 50 ms on
  /// a haptic device, off on the mouse, mouse-hand and simulated devices, whose stalls hold no force against
  /// a hand (a busy desktop stalls a loop without real-time rights for tens of ms, which would end the
  /// trial).
  std::optional<double> watchdog_s;
  std::string library_version;
};

/// Runs the trainer until the window is closed, Q or Esc is pressed, a stop signal (SIGINT, SIGTERM, SIGHUP,
/// SIGUSR1, SIGUSR2, SIGXCPU) arrives, the device fails, or (with exit_after_s) the time runs out or every
/// character had its trial. Prints the character boxes to stdout first, a measurement summary to stderr last.
/// Returns 0, 1 when a trial ended with a device fault or could not be saved, 128 + N after stop signal N. A
/// lost display ends the process with kDisplayLostStatus (4, x11_errors.hpp) once the running trial is saved.
/// Throws Error (InvalidArgument, DeviceNotFound, ...) when it cannot start (no display, a bad option).
int run_trainer(const TrainerOptions& options);

/// Throws Error ("cannot open a window: ... DISPLAY is '...'") when no window can be opened because there is
/// no X display (GLFW cannot initialise), as `run_trainer` and `run_trainer_session` would: a caller refuses
/// before it makes anything (a session's folder).
void check_display();

/// A study session in the window: `calligraphy session run` on a device a person moves.
struct TrainerSessionOptions {
  SessionFolder* session = nullptr;  ///< the session to run (its unsaved trials)
  /// registry, load_character, should_stop (e.g. the process's stop signals), pacing; the trainer sets
  /// host (which gives each trial its display channel) and lock_memory (off).
  SessionRunOptions run;
  /// A character to draw (its model and outlines), for every character of the plan.
  std::function<TrainerCharacter(char32_t)> load_character;
  int width_px = 1280;
  int height_px = 800;
  std::string screenshot;        ///< PNG written after the last planned trial's outcome, or at exit
  std::string quiz_screenshots;  ///< non-empty: a folder where a PNG is written after each judged stroke
  bool engineer = false;         ///< the engineer's panel (TrainerOptions::engineer); else the learner's
  double exit_after_s = 0.0;     ///< > 0: unattended (trials start by themselves); quit after this long
  std::string library_version;
};

/// Runs `run_session` on a thread of its own while the window shows, trial by trial, the characters and
/// the condition of the next trial (started with Space, or after a second when unattended), the break
/// countdowns, each trial live as `run_trainer` does, and each trial's outcome. Esc, Q, closing the
/// window or a stop signal ends the session: the running trial is kept as an attempt (so `session resume`
/// goes on with it). Returns what run_session returned; rethrows what it threw. Throws Error when no
/// window can open.
SessionRunResult run_trainer_session(const TrainerSessionOptions& options);

/// Registers the trainer's pointer devices ("mouse", "mouse-hand") in `registry` (nothing for a name already
/// taken). They move only while a trainer window is open.
void register_trainer_devices(DeviceRegistry& registry);

}  // namespace calligraphy::trainer
