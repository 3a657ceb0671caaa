// The trainer's window loop (trainer_window.hpp): the window thread draws at the display rate from the
// display channel's snapshot and queues, never waiting on the servo thread; each trial runs on a worker
// thread through run_trial with real-time pacing, the ServoLoop on its own thread.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "calligraphy/core/stop_signals.hpp"
#include "trainer/pointer_devices.hpp"
#include "trainer/trainer_window.hpp"
#include "trainer/x11_errors.hpp"

namespace calligraphy::trainer {
namespace {

constexpr double kFramePeriodS = 1.0 / 60.0;

// The character boxes in window pixels ("box 0 永 x=64 y=24 size=752"), for tests and tools that move the
// pointer over a character: on standard error, only when CALLIGRAPHY_PRINT_BOXES is set (docs/trainer.md).
// Standard output carries none of them.
bool print_boxes() {
  const char* value = std::getenv("CALLIGRAPHY_PRINT_BOXES");
  return value != nullptr && *value != '\0' && std::string_view(value) != "0";
}
// After a lost display: how long the trial (or the session's thread) may take to stop and be saved.
constexpr auto kSaveAfterLostDisplay = std::chrono::seconds(5);

}  // namespace

TrainerApp::TrainerApp(const TrainerOptions& options, DeviceInfo device_info, bool hardware,
                       const SessionLink* session)
    : options_(options),
      quiz_log_(session ? "calligraphy session" : "calligraphy train", options.quiz_screenshots),
      learner_device_(learner_device(options.device, hardware, options.simulated_writer)) {
  for (const TrainerCharacter& c : options.characters) art_.push_back(prepare_art(c));
  if (session != nullptr) {
    session_.emplace(*session, options_.characters, unattended());
    every_character_art_ = art_;
  } else {
    practice_.emplace(options_, std::move(device_info), hardware);
  }
}

int TrainerApp::run() {
  set_display_lost_ending([this] { end_after_lost_display(); });
  open_window();
  // The session folder only once the window is open: a display that cannot be opened leaves no session
  // that started and never stopped.
  if (practice_) practice_->open_practice_folder();
  layout_.emplace(session_ ? 1 : options_.characters.size(), options_.width_px, options_.height_px,
                  kPanelWidthPx);
  if (session_) art_.resize(1);
  for (std::size_t k = 0; k < layout_->count() && !session_ && print_boxes(); ++k) {
    const ScreenBox& b = layout_->box(k);
    std::fprintf(stderr, "box %zu %s x=%.0f y=%.0f size=%.0f\n", k, options_.characters[k].utf8.c_str(),
                 b.x_px, b.y_px, b.size_px);
  }
  std::fflush(stderr);
  started_ = Clock::now();
  if (practice_) practice_->start_trial(0);
  loop();
  close_window();
  set_display_lost_ending({});
  print_measurements();
  const int signal = StopSignals::received();
  if (signal != 0 && practice_) {
    std::fprintf(stderr, "calligraphy train: stopped by %s\n", signal_name(signal));
    practice_->log_stop(signal_name(signal));
    if (exit_status() == 0) return exit_status_after(signal);
  }
  return exit_status();
}

// 1 when a trial ended with a device fault or could not be saved, or a screenshot not written.
int TrainerApp::exit_status() const {
  return screenshot_failed_ || (practice_ && practice_->failed()) ? 1 : 0;
}

// The I/O error handler's ending (x11_errors.hpp), on the window thread inside Xlib: no Xlib, GLFW or GL
// call. The servo side stops (zero force, forces off) and the trial is saved as interrupted with every
// tick, as when the window is closed; a study session's thread keeps it as an attempt and logs the stop.
void TrainerApp::end_after_lost_display() {
  const auto deadline = Clock::now() + kSaveAfterLostDisplay;
  const auto wait_until = [&deadline](const auto& done) {
    while (!done() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return done();
  };
  if (session_) {
    session_->request_stop();
    if (wait_until([this] { return session_->finished(); })) {
      std::fprintf(stderr,
                   "calligraphy session: stopped: the display was lost; the running trial is kept as an "
                   "attempt; resume with: calligraphy session resume SESSION_FOLDER\n");
    } else {
      std::fprintf(stderr, "calligraphy session: error: the session did not end within %lld s\n",
                   static_cast<long long>(kSaveAfterLostDisplay.count()));
    }
    return;
  }
  practice_->stop_trial();
  if (practice_->has_trial()) {
    if (wait_until([this] { return practice_->trial_done(); })) {
      practice_->finish_trial(quiz_log_);
    } else {
      std::fprintf(stderr, "calligraphy train: error: the trial did not end within %lld s\n",
                   static_cast<long long>(kSaveAfterLostDisplay.count()));
    }
  }
  practice_->log_stop("display_lost");
}

bool TrainerApp::unattended() const { return options_.exit_after_s > 0.0; }

// ---- The loop.
void TrainerApp::loop() {
  auto next_frame = Clock::now();
  while (true) {
    glfwPollEvents();
    const bool closed = glfwWindowShouldClose(window_) != 0 || x11_error_seen();
    if (closed || StopSignals::received() != 0) quit_ = true;
    if (closed && practice_) practice_->note_stop_cause("closing the window");
    if (unattended() && seconds_since_start() >= options_.exit_after_s) {
      quit_ = true;
      if (practice_) practice_->note_stop_cause("--exit-after");
    }
    handle_keys();
    if (quit_ && !quit_seen_) {  // the picture at exit shows the window as it was when the exit came
      const bool shows_something = trial_view() != nullptr || (practice_ && practice_->demonstrating());
      if (!options_.screenshot.empty() && !screenshot_taken_ && !x11_error_seen() && shows_something)
        render(true);
      quit_seen_ = true;
    }
    if (session_) {
      if (quit_) session_->request_stop();
      session_->follow(quiz_log_,
                       [this](const std::vector<std::size_t>& characters) { show_row(characters); });
      if (session_->finished() && (quit_ || unattended())) break;
    }
    if (practice_) {
      practice_->follow_trial(quit_, quiz_log_);
      if (practice_->window_should_close()) quit_ = true;
      if (!practice_->has_trial()) {
        if (quit_) break;
        practice_->start_next_trial();
      }
    }
    update_pointer();
    if (x11_error_seen()) continue;  // the window is gone: no drawing, only the ending above
    const bool take_screenshot = !options_.screenshot.empty() && !screenshot_taken_ && screenshot_due();
    render(take_screenshot);
    next_frame += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kFramePeriodS));
    if (next_frame < Clock::now()) next_frame = Clock::now();
    std::this_thread::sleep_until(next_frame);
  }
  // The last character's trial ended in this very iteration: its summary, after the last stroke.
  if (!options_.screenshot.empty() && !screenshot_taken_ && !x11_error_seen() && trial_view()) render(true);
  // A stroke judged as the trial ended (the pen still down): the frame that shows it.
  if (quiz_log_.screenshot_requested() && !x11_error_seen() && trial_view()) render(false);
}

// After the last character's trial, or the last planned trial's outcome.
bool TrainerApp::screenshot_due() const {
  return practice_ ? practice_->last_character_ended() : session_->last_trial_ended();
}

double TrainerApp::seconds_since_start() const {
  return std::chrono::duration<double>(Clock::now() - started_).count();
}

// A panel button: as its key.
void TrainerApp::act(PanelAction action) {
  if (!practice_) return;
  switch (action) {
    case PanelAction::demonstrate:
      practice_->demonstrate();
      break;
    case PanelAction::restart:
      practice_->ask_for(NextAction::repeat);
      break;
    case PanelAction::next:
      practice_->ask_for(NextAction::next);
      break;
    case PanelAction::none:
      break;
  }
}

void TrainerApp::handle_keys() {
  act(action_);
  action_ = PanelAction::none;
  for (const int key : keys_) {
    switch (key) {
      case GLFW_KEY_Q:
      case GLFW_KEY_ESCAPE:
        quit_ = true;
        if (practice_) practice_->note_stop_cause("Q or Esc");
        break;
      case GLFW_KEY_SPACE:
        if (session_) session_->start_trial();
        break;
      case GLFW_KEY_R:
        if (practice_) practice_->ask_for(NextAction::repeat);
        break;
      case GLFW_KEY_N:
        if (practice_) practice_->ask_for(NextAction::next);
        break;
      case GLFW_KEY_D:
        if (practice_) practice_->demonstrate();
        break;
      case GLFW_KEY_G:
        if (practice_) practice_->toggle_guidance();
        break;
      case GLFW_KEY_M:
        if (practice_) practice_->next_guidance_mode();
        break;
      default:
        break;
    }
  }
  keys_.clear();
}

// The pointer in the running trial's metres, for the mouse devices (lock-free; read by the servo thread).
void TrainerApp::update_pointer() {
  const TrialView* view = trial_view();
  if (view == nullptr || !layout_) return;
  double x = 0.0;
  double y = 0.0;
  glfwGetCursorPos(window_, &x, &y);
  const bool in_area = x >= 0.0 && x < layout_->area_width_px() && y >= 0.0 && y < layout_->height_px();
  const bool pressed = in_area && glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const Vec2 trial_m =
      view->whole_row ? layout_->screen_to_row(Vec2(x, y)) : layout_->to_trial(view->character, Vec2(x, y));
  pointer_input().set(trial_m.x(), trial_m.y(), pressed);
}

const TrialView* TrainerApp::trial_view() const { return practice_ ? practice_->view() : session_->view(); }

// A session's trial: the row becomes its characters.
void TrainerApp::show_row(const std::vector<std::size_t>& characters) {
  art_.clear();
  for (const std::size_t k : characters) art_.push_back(every_character_art_[k]);
  layout_.emplace(art_.size(), options_.width_px, options_.height_px, kPanelWidthPx);
  for (std::size_t k = 0; k < layout_->count() && print_boxes(); ++k) {
    const ScreenBox& b = layout_->box(k);
    std::fprintf(stderr, "box %zu %s x=%.0f y=%.0f size=%.0f\n", k,
                 options_.characters[characters[k]].utf8.c_str(), b.x_px, b.y_px, b.size_px);
  }
  std::fflush(stderr);
}

}  // namespace calligraphy::trainer
