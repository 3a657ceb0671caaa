#pragma once
// TrainerApp: the window of `calligraphy train` and of a study session in the window (trainer.hpp). Its
// methods live in files by job: trainer_app.cpp (construction, the loop, keys, pointer), trainer_window.cpp
// (window, fonts, drawing, screenshots), trainer_trials.cpp (a trial's start and end, measurements),
// a study session is followed by a HostedSessionView, the quiz's verdicts and refused strokes go to a
// QuizLog.
#include <imgui.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/study/practice_session.hpp"
#include "calligraphy/trial/trial.hpp"
#include "trainer/hosted_session_view.hpp"
#include "trainer/layout.hpp"
#include "trainer/live_quiz.hpp"
#include "trainer/panel.hpp"
#include "trainer/quiz_log.hpp"
#include "trainer/scene_view.hpp"
#include "trainer/session_host.hpp"
#include "trainer/stop_reason.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"
#include "trainer/trial_worker.hpp"

struct GLFWwindow;

namespace calligraphy::trainer {

constexpr double kPanelWidthPx = 400.0;
constexpr double kAdvanceDelayS = 1.0;  // unattended: pause on a trial's summary before the next

using Clock = std::chrono::steady_clock;

enum class NextAction { none, repeat, next, quit };

class TrainerApp {
 public:
  TrainerApp(const TrainerOptions& options, DeviceInfo device_info, bool hardware,
             const SessionLink* session = nullptr);

  int run();

 private:
  // the loop, keys and pointer (trainer_app.cpp)
  [[nodiscard]] std::string condition_name() const;
  [[nodiscard]] bool unattended() const;
  void loop();
  double seconds_since_start() const;
  void handle_keys();
  void update_pointer();
  void end_after_lost_display();

  // window, fonts, drawing (trainer_window.cpp)
  void open_window();
  void load_fonts();
  void close_window();
  void render(bool take_screenshot);

  // a trial's start and end, measurements (trainer_trials.cpp)
  void start_trial(std::size_t character);
  void finish_trial();
  void save_recording(TrialView& view, const TrialResult& result);
  void log_stop(const std::string& reason);
  void print_measurements() const;

  // a study session's trials, each shown as its row
  void follow_session();
  void show_row(const std::vector<std::size_t>& characters);
  [[nodiscard]] const TrialView* trial_view() const;

  // the characters of the practice trial `view` shows, in its scene's order, for the quiz log
  [[nodiscard]] std::span<const std::string> characters_utf8(const TrialView& view) const;

  TrainerOptions options_;
  DeviceInfo device_info_;
  bool hardware_ = false;
  std::optional<PracticeSession> practice_;
  std::optional<HostedSessionView> session_;
  std::vector<CharacterArt> every_character_art_;  // a session's: each trial's row is drawn from it
  TrialOptions trial_options_;
  SimulationOptions trial_simulation_;  ///< the simulated writer of the trial (a hand-port device only)
  Clock::time_point trial_wall_start_;
  std::vector<CharacterArt> art_;
  std::vector<std::vector<int>> typical_ids_;
  GLFWwindow* window_ = nullptr;
  ImFont* large_font_ = nullptr;
  ImVector<ImWchar> glyph_ranges_;
  std::optional<WindowLayout> layout_;
  std::vector<int> keys_;
  TrialWorker worker_;
  std::unique_ptr<DisplayChannel> channel_;
  std::optional<TrialView> view_;
  std::size_t trials_started_ = 0;
  std::string trial_start_utc_;
  bool guidance_ = true;
  GuidanceMode guidance_mode_ = GuidanceMode::fixed;
  double guidance_gain_ = 1.0;
  double assist_band_m_ = AssistAsNeededGuidance{}.band_m;  // assist-as-needed: the next trial's band
  bool condition_outputs_force_ = true;
  bool quit_ = false;
  bool quit_seen_ = false;
  bool stop_logged_ = false;
  NextAction pending_ = NextAction::none;
  std::optional<Clock::time_point> advance_at_;
  bool screenshot_due_ = false;
  QuizLog quiz_log_;
  bool screenshot_taken_ = false;
  Clock::time_point started_;
  std::size_t frames_ = 0;
  std::vector<double> latencies_ms_;
  int status_ = 0;
};

}  // namespace calligraphy::trainer
