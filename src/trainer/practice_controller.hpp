#pragma once
// The practice of `calligraphy train`: one trial at a time on a worker thread (trial_worker.hpp), started
// for a character of the row and finished once the worker is done: its result saved into the practice
// folder (study's PracticeSession) and as a teacher's recording when asked, summarised on stderr; the
// guidance of the next trial (on or off, its mode, the fading gain or the assist-as-needed band from this
// trial's outcome); the keys' repeat and next, and the unattended advance; the practice's stop logged.
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/study/practice_session.hpp"
#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/trial.hpp"
#include "trainer/demonstration.hpp"
#include "trainer/panel.hpp"
#include "trainer/quiz_log.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"
#include "trainer/trial_worker.hpp"

namespace calligraphy::trainer {

/// Unattended: the pause on a trial's summary before the next (a session's host waits as long).
constexpr double kAdvanceDelayS = 1.0;

/// What a key asked for once the trial ends: the same character again, the next one, or the stroke order
/// demonstrated and then the same character again.
enum class NextAction { none, repeat, next, demonstrate };

class PracticeController {
 public:
  using Clock = std::chrono::steady_clock;

  /// `options` outlive the controller. `device_info` and `hardware` describe the device, for the practice
  /// folder and the watchdog's default.
  PracticeController(const TrainerOptions& options, DeviceInfo device_info, bool hardware);

  /// With options.session_dir: creates the practice folder the trials are saved into (and says where).
  void open_practice_folder();

  /// Starts the trial of character `character` of the row on the worker thread; first, when attended and
  /// not yet shown, the demonstration of its stroke order (the trial starts once it ends: no trial, so
  /// no force, while it runs).
  void start_trial(std::size_t character);
  /// D or the panel's button: the running trial ends (kept as R keeps it) and the stroke order of its
  /// character is demonstrated, then its trial starts again; during a demonstration, skips the rest of it.
  void demonstrate();
  /// A demonstration runs (no trial does).
  [[nodiscard]] bool demonstrating() const noexcept { return demo_.has_value(); }
  /// The demonstration as it is now, to draw; nullopt when none runs.
  [[nodiscard]] std::optional<DemoView> demo_view() const;
  /// Once a frame: stops the running trial when the window quits (`quitting`), a key asked for another
  /// trial or its quiz is complete; drains its display channel into the view, logging the quiz's verdicts
  /// and refusals; finishes it once the worker is done.
  void follow_trial(bool quitting, QuizLog& quiz_log);
  /// Once a frame while no trial runs: the trial a key asked for, or the next one when unattended.
  void start_next_trial();
  /// The worker is done: takes its result, saves it, and shows the summary.
  void finish_trial(QuizLog& quiz_log);
  /// Asks the running trial to end (interrupted, every tick kept).
  void stop_trial();
  /// The practice's session_stopped event (once), when the window ends early.
  void log_stop(const std::string& reason);
  /// What is about to stop the running trial, for its summary line ("--exit-after", "Q or Esc"): the first
  /// cause given since the trial started is kept. A stop signal or a lost display names itself.
  void note_stop_cause(std::string cause) {
    if (stop_cause_.empty()) stop_cause_ = std::move(cause);
  }

  // The keys: R and N ask for a trial once this one ends; G and M set the next trial's guidance.
  void ask_for(NextAction action) noexcept { pending_ = action; }
  void toggle_guidance() noexcept;
  void next_guidance_mode();

  /// A trial was started and its result not taken yet.
  [[nodiscard]] bool has_trial() const noexcept { return worker_.active(); }
  /// A trial runs on the worker thread: its snapshots are live.
  [[nodiscard]] bool trial_running() const noexcept { return worker_.active() && !worker_.done(); }
  /// The started trial's worker is done: its result is ready.
  [[nodiscard]] bool trial_done() const noexcept { return worker_.done(); }
  /// The trial shown, or null before the first.
  [[nodiscard]] const TrialView* view() const noexcept { return view_ ? &*view_ : nullptr; }
  /// The scene of the trial last started.
  [[nodiscard]] const Scene& scene() const noexcept { return worker_.scene(); }
  /// The panel's practice lines: the character, and the next trial's guidance.
  void fill_panel(PanelInput& panel) const;
  /// The window should close: the device failed, or an unattended run gave every character its trial.
  [[nodiscard]] bool window_should_close() const noexcept { return close_window_; }
  /// The last character of the row had its trial (the picture at the end is due).
  [[nodiscard]] bool last_character_ended() const noexcept { return last_character_ended_; }
  /// A trial ended with a device fault or the watchdog, or a trial, recording or the log was not written.
  [[nodiscard]] bool failed() const noexcept { return failed_; }

 private:
  [[nodiscard]] std::string condition_name() const;
  void launch_trial(std::size_t character);
  void begin_demonstration(std::size_t character);
  [[nodiscard]] bool unattended() const noexcept { return options_.exit_after_s > 0.0; }
  // The characters of the practice trial `view` shows, in its scene's order: its one character.
  [[nodiscard]] std::span<const std::string> characters_utf8(const TrialView& view) const;
  void adapt_guidance(const TrialView& view);
  void save_recording(TrialView& view, const TrialResult& result);
  std::string save_trial(TrialView& view, const TrialResult& result);
  [[nodiscard]] std::string trial_summary(const TrialView& view, const TrialResult& result,
                                          const WritingMetrics& writing, const std::string& saved) const;

  const TrainerOptions& options_;
  DeviceInfo device_info_;
  bool hardware_ = false;
  /// The quiz's options, judging with the trials' tolerances and start neighbourhood (set as they start).
  QuizOptions quiz_options_;
  std::vector<std::vector<int>> typical_ids_;  // per character of the row
  std::optional<PracticeSession> practice_folder_;
  // The next trial's guidance.
  bool guidance_ = true;
  GuidanceMode guidance_mode_ = GuidanceMode::fixed;
  double guidance_gain_ = 1.0;
  double assist_band_m_ = AssistAsNeededGuidance{}.band_m;  // assist-as-needed: the next trial's band
  bool condition_outputs_force_ = true;
  // The trial last started.
  // The channel outlives the worker, whose trial thread publishes into it until it is joined.
  std::unique_ptr<DisplayChannel> channel_;
  TrialWorker worker_;
  std::optional<TrialView> view_;
  std::size_t trials_started_ = 0;
  TrialOptions trial_options_;
  SimulationOptions trial_simulation_;  ///< the simulated writer of the trial (a hand-port device only)
  std::string trial_start_utc_;
  Clock::time_point trial_wall_start_;
  std::string stop_cause_;  ///< what stopped the running trial, when not a signal or a lost display
  // The stroke-order demonstration, when one runs: the character laid out as its trial lays it out.
  struct Demonstration {
    std::size_t character = 0;
    Scene scene;
    DemoSchedule schedule;
    Clock::time_point started;
  };
  std::optional<Demonstration> demo_;
  std::vector<bool> demonstrated_;  // per character of the row: its stroke order was shown
  // What comes after it.
  NextAction pending_ = NextAction::none;
  std::optional<Clock::time_point> advance_at_;
  bool close_window_ = false;
  bool last_character_ended_ = false;
  bool stop_logged_ = false;
  bool failed_ = false;
};

}  // namespace calligraphy::trainer
