#pragma once
// TrainerApp: the window of `calligraphy train` and of a study session in the window (trainer.hpp), the
// shell around the parts it composes: the PracticeController of `train` or the HostedSessionView of a
// session (one of the two), and the QuizLog both write to. It owns the GLFW window, the fonts, the row of
// characters drawn and the frame loop, and routes the keys, the pointer and a lost display to the part
// that runs. Its methods: trainer_window_loop.cpp (construction, the loop, keys, pointer, a lost display),
// trainer_window.cpp (window, fonts, drawing, screenshots, measurements).
#include <imgui.h>

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "trainer/hosted_session_view.hpp"
#include "trainer/layout.hpp"
#include "trainer/learner_text.hpp"
#include "trainer/practice_controller.hpp"
#include "trainer/quiz_log.hpp"
#include "trainer/scene_view.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"

struct GLFWwindow;

namespace calligraphy::trainer {

class TrainerApp {
 public:
  /// Practice with `options` on the device `device_info` (`hardware`: a haptic device), or, with
  /// `session`, the window of that study session (which outlives the app).
  TrainerApp(const TrainerOptions& options, DeviceInfo device_info, bool hardware,
             const SessionLink* session = nullptr);
  TrainerApp(const TrainerApp&) = delete;  // its parts refer to its options
  TrainerApp& operator=(const TrainerApp&) = delete;

  /// Opens the window and runs it until it closes; returns the exit status (trainer.hpp, run_trainer).
  int run();

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr double kPanelWidthPx = 400.0;

  // the loop, keys, pointer and a lost display (trainer_window_loop.cpp)
  [[nodiscard]] bool unattended() const;
  void loop();
  [[nodiscard]] double seconds_since_start() const;
  void handle_keys();
  void update_pointer();
  void end_after_lost_display();
  void show_row(const std::vector<std::size_t>& characters);
  void act(PanelAction action);
  [[nodiscard]] const TrialView* trial_view() const;
  [[nodiscard]] bool screenshot_due() const;
  [[nodiscard]] int exit_status() const;

  // window, fonts, drawing (trainer_window.cpp)
  void open_window();
  void load_fonts();
  void close_window();
  void render(bool take_screenshot);
  void print_measurements() const;

  const TrainerOptions options_;
  // The part that runs: `train`'s practice, or a study session's view.
  std::optional<PracticeController> practice_;
  std::optional<HostedSessionView> session_;
  QuizLog quiz_log_;
  LearnerDevice learner_device_ = LearnerDevice::mouse;  // what the device line says
  // The window and what it draws.
  GLFWwindow* window_ = nullptr;
  ImFont* large_font_ = nullptr;
  ImVector<ImWchar> glyph_ranges_;
  std::optional<WindowLayout> layout_;
  std::vector<CharacterArt> art_;                  // the row drawn
  std::vector<CharacterArt> every_character_art_;  // a session's: each trial's row is drawn from it
  std::vector<int> keys_;
  bool quit_ = false;
  bool quit_seen_ = false;
  bool screenshot_taken_ = false;
  bool screenshot_failed_ = false;
  PanelAction action_ = PanelAction::none;  // a panel button pressed in the last frame
  // Measurements.
  Clock::time_point started_;
  std::size_t frames_ = 0;
  std::vector<double> latencies_ms_;
};

}  // namespace calligraphy::trainer
