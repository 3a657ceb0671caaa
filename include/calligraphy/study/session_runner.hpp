#pragma once
/// \file session_runner.hpp
/// Runs the trials of a session folder that are not saved yet, in the planned order, one `run_trial`
/// each (trial/runner.hpp): lock-step with a simulated writer on a simulated or emulated device, in real
/// time on a device a person moves. Each trial is scored (`score_trace` on the recorded pen trace, quiz
/// conditions also through a `QuizSession`) and saved as it ends (session_folder.hpp); the log records
/// every step. A trial that ends interrupted or with a device fault is kept as an attempt, never as the
/// saved trial, so `run_session` on the same folder later resumes with it. A `SessionHost` (a trainer
/// window, a terminal) is told what comes next and takes the breaks.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/model/character.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy {

/// What a saved trial came to, for the host.
struct TrialOutcome {
  std::string end_reason;  ///< TrialEnd as text
  bool saved = false;      ///< saved as the trial (else kept as an attempt)
  double time_s = 0.0;     ///< first to last pen-down sample [s] (total_time_s); NaN: the pen never touched
  double mean_deviation_mm = 0.0;  ///< NaN when no stroke was written
  std::string json_file;           ///< the saved trial's or the attempt's JSON
};

/// Who hosts a session: the trainer window, a terminal prompt, or nobody (the default does nothing).
class SessionHost {
 public:
  virtual ~SessionHost() = default;
  /// Before a trial starts: show what is to be written (`trial.characters`, the condition). `total` is the
  /// number of planned trials.
  virtual void before_trial(const PlannedTrial& trial, std::size_t total);
  /// A rest of `seconds` before `trial`: return when it is over or `should_stop` turns true. Called only
  /// for a human writer; a simulated writer's breaks are logged, not waited.
  virtual void rest(double seconds, const PlannedTrial& trial, const std::function<bool()>& should_stop);
  /// After a trial ended (saved or kept as an attempt).
  virtual void after_trial(const PlannedTrial& trial, const TrialOutcome& outcome);
  /// Just before `trial` runs, on the runner's thread: where it publishes what a window shows
  /// (TrialRunInputs::display; not owned: the host keeps it alive until it is asked again or the session
  /// ends). `acceptance` is how its strokes are judged (the condition's), for a window that shows pen-downs
  /// the trial never reaches. nullptr (the default): nowhere.
  virtual DisplayChannel* display_for(const PlannedTrial& trial, const StrokeAcceptance& acceptance);
};

/// Options of `run_session`.
struct SessionRunOptions {
  /// Where the device named in the session is created (not owned): its owner's registry (the command
  /// line's, Python's, a test's). Required: run_session throws InvalidArgument without one.
  const DeviceRegistry* registry = nullptr;
  /// Loads a character's model; empty: the standard set (CharacterLibrary::standard(): every
  /// hanzi-writer-data character).
  std::function<Character(char32_t)> load_character;
  /// Polled between trials and during each trial (TrialOptions::should_stop); true ends the session after
  /// keeping the running trial as an attempt.
  std::function<bool()> should_stop;
  /// Why should_stop turned true, read once it did: e.g. "SIGTERM", "display_lost". Logged as the
  /// `reason` of `trial_interrupted` and `session_stopped`, and the interrupted attempt's `abort_reason`
  /// says "stopped by REASON"; empty (or no function): the reason is "interrupted".
  std::function<std::string()> stop_reason;
  SessionHost* host = nullptr;  ///< nullptr: nobody is told
  /// Overrides the session's pacing for this run (e.g. a session begun in real time resumed lock-step);
  /// nullopt: the pacing in session.json.
  std::optional<TrialPacing> pacing;
  /// Lock the process's memory in a real-time trial (TrialRunInputs::lock_memory): a session's program does;
  /// a window process sets false (its GL driver maps memory all the time).
  bool lock_memory = true;
};

/// What `run_session` did.
struct SessionRunResult {
  std::size_t planned = 0;       ///< trials in the plan
  std::size_t saved_before = 0;  ///< saved when the run began
  std::size_t saved_now = 0;     ///< saved by this run
  std::size_t attempts_kept = 0;
  bool interrupted = false;  ///< should_stop ended the run
  bool device_failed = false;
  /// A trial's files could not be written (a disk filled meanwhile): the run stopped there, every trial saved
  /// before stays saved and the session can be resumed.
  bool save_failed = false;
  std::string failure;  ///< the device's message when it failed; what could not be saved, and why
  [[nodiscard]] bool complete() const { return saved_before + saved_now == planned; }
};

/// What the guidance of a `fading`, `assist-as-needed`, `skill-adaptive` or `replay` trial takes from the
/// session (docs/experiments.md): the runner works it out from the saved trials and the teachers kept in the
/// session folder.
struct TrialGuidance {
  double gain = 1.0;  ///< `fading`: the trial's gain in [0, 1] (ForceLawParameters)
  double band_m = AssistAsNeededGuidance{}.band_m;  ///< `assist-as-needed`: the trial's band [m] >= 0
  /// `skill-adaptive`: the mode chosen for the trial (fixed or error amplification); nullopt: fixed.
  std::optional<GuidanceMode> mode;
  std::vector<TeacherSample> teacher;  ///< `replay`: the teacher's pen, device frame [m], times [s]
  std::string teacher_file;            ///< `replay`: its file in the session folder ("teachers/....json")
};

/// The trial specification (trial_spec.hpp) of `trial` of `condition` in `session`: its characters, the
/// session's device, writer, profile and pacing, a seed of the simulated subject's own per trial (from the
/// subject's seed, the trial's index and the session's number), servo rate and duration from the protocol,
/// the guidance mode and parameters of the condition's law as its schedule sets it for `guidance` (the
/// repetition's gain, band or mode; a replay's teacher), guidance off without one (`vision`, `quiz`). Not
/// checked yet: its runner adds what it knows (a pacing, a learning subject's
/// skills) and checks it once, with a replay's teacher from `study_teacher_source(condition)`. Throws
/// InvalidArgument naming the condition for a `replay` condition without a teacher in `guidance`.
[[nodiscard]] TrialSpec study_trial_spec(const SessionManifest& session, const StudyCondition& condition,
                                         const PlannedTrial& trial, const TrialGuidance& guidance = {});

/// Where a study trial's replay teacher comes from: the samples kept in the session folder
/// (TrialRunInputs::teacher), never a file the specification names.
[[nodiscard]] inline TeacherSource study_teacher_source(const StudyCondition& condition) noexcept {
  return replays_teacher(condition) ? TeacherSource::samples : TeacherSource::file;
}

/// The runner's options of that specification on a device stating no limits: those of the trial's whole
/// trial as sessions and cohorts build it (the condition's force law over the one the specification states:
/// the quiz's acceptance, the replay's lead, the condition's guidance stiffness), with the replay's teacher
/// of `guidance`; checked (the check of a plan before its first trial). Throws InvalidArgument naming
/// the condition for a `replay` condition without a teacher in `guidance`, and what `TrialSpec::validate` and
/// `TrialOptions::validate` throw.
[[nodiscard]] TrialOptions study_trial_options(const SessionManifest& session,
                                               const StudyCondition& condition, const PlannedTrial& trial,
                                               const TrialGuidance& guidance = {});

/// Runs every unsaved trial of `session` (see the file comment). A `fading` trial's gain follows the
/// previous saved repetition of its item in the condition; a `replay` trial follows the teacher kept in
/// the session folder's teachers/ (copied from the protocol, or recorded by a skilled simulated writer
/// when the protocol names none), each named with its SHA-256 in the trial's record. Throws
/// InvalidArgument before any trial when `options` gives no registry, a planned condition cannot run or a
/// simulated writer is asked to move a device a person holds, DeviceNotFound when the device is not in the
/// registry, CharacterNotFound for a missing character, DataError before any trial when the session cannot be
/// written
/// (`SessionFolder::check_writable`), and DataError when the log cannot be written. A trial whose files
/// cannot be saved ends the run with `save_failed`; what was saved before stays saved.
SessionRunResult run_session(SessionFolder& session, const SessionRunOptions& options);

/// The end of the log of a session whose every planned trial is saved but whose log does not end with
/// `session_completed`: a run killed (or stopped) after its last trial's record was saved, before it logged
/// the save or the end. Logs what `run_session` on it would: each saved trial the log does not name
/// (`trial_saved`, marked `recovered`), `session_resumed` and `session_completed`; returns true. A session
/// with a trial unsaved, or whose log ends with `session_completed`, is left as it is (false). Throws
/// DataError naming the log or a record that cannot be read, or the log when it cannot be written.
bool complete_session_log(SessionFolder& session);

}  // namespace calligraphy
