// The trainer's window loop (trainer.hpp): the window thread draws at the display rate from the
// display channel's snapshot and queues, never waiting on the servo thread; each trial runs on a worker
// thread through run_trial with real-time pacing, the ServoLoop on its own thread.
#include "trainer/trainer_app.hpp"

#include <algorithm>
#include <span>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/stop_signals.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "trainer/pointer_devices.hpp"
#include "trainer/x11_errors.hpp"

namespace calligraphy::trainer {
namespace {

constexpr double kFramePeriodS = 1.0 / 60.0;
// After a lost display: how long the trial (or the session's thread) may take to stop and be saved.
constexpr auto kSaveAfterLostDisplay = std::chrono::seconds(5);

}  // namespace

TrainerApp::TrainerApp(const TrainerOptions& options, DeviceInfo device_info, bool hardware,
                       const SessionLink* session)
    : options_(options),
      device_info_(std::move(device_info)),
      hardware_(hardware),
      quiz_log_(session ? "calligraphy session" : "calligraphy train", options.quiz_screenshots) {
  for (const TrainerCharacter& c : options.characters) {
    art_.push_back(prepare_art(c));
    std::vector<int> ids;
    for (const Stroke& s : c.model.strokes) ids.push_back(s.typical_id);
    typical_ids_.push_back(std::move(ids));
  }
  guidance_ = options.guidance && !options.quiz;  // a quiz is force-free but for the paper
  // The quiz judges with the renderer's tolerances and start neighbourhood: those of the trials start_trial
  // runs (default ForceLawParameters, a default scene layout), also in the practice protocol saved first.
  options_.quiz_options.acceptance = TrialOptions{}.force.acceptance;
  options_.quiz_options.start_radius_m = SceneLayout{}.start_radius_m;
  guidance_mode_ = options.guidance_mode;
  guidance_gain_ = options.guidance_gain;
  condition_outputs_force_ = options.device != "mouse";
  if (session != nullptr) {
    session_.emplace(*session, options_.characters, unattended());
    every_character_art_ = art_;
  }
}

int TrainerApp::run() {
  if (!options_.session_dir.empty()) {
    PracticeSetup setup;
    setup.root = options_.session_dir;
    setup.subject = options_.subject;
    for (const TrainerCharacter& c : options_.characters) setup.characters_utf8 += c.utf8;
    setup.first_condition = condition_name();
    setup.device = options_.device;
    setup.device_info = device_info_;
    setup.hardware = hardware_;
    setup.simulated_writer = options_.simulated_writer;
    setup.writer_profile = options_.writer_profile;
    setup.writer_seed = options_.seed;
    setup.quiz = options_.quiz_options;
    practice_.emplace(setup);
    std::fprintf(stderr, "calligraphy train: saving into %s\n", practice_->path().c_str());
  }
  set_display_lost_ending([this] { end_after_lost_display(); });
  open_window();
  layout_.emplace(session_ ? 1 : options_.characters.size(), options_.width_px, options_.height_px,
                  kPanelWidthPx);
  if (session_) art_.resize(1);
  for (std::size_t k = 0; k < layout_->count() && !session_; ++k) {
    const ScreenBox& b = layout_->box(k);
    std::printf("box %zu %s x=%.0f y=%.0f size=%.0f\n", k, options_.characters[k].utf8.c_str(), b.x_px,
                b.y_px, b.size_px);
  }
  std::fflush(stdout);
  started_ = Clock::now();
  if (!session_) start_trial(0);
  loop();
  close_window();
  set_display_lost_ending({});
  print_measurements();
  const int signal = StopSignals::received();
  if (signal != 0 && !session_) {
    std::fprintf(stderr, "calligraphy train: stopped by %s\n", signal_name(signal));
    log_stop(signal_name(signal));
    if (status_ == 0) status_ = exit_status_after(signal);
  }
  return status_;
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
  if (worker_.active() && !worker_.done()) worker_.request_stop();
  if (worker_.active()) {
    if (wait_until([this] { return worker_.done(); })) {
      finish_trial();
    } else {
      std::fprintf(stderr, "calligraphy train: error: the trial did not end within %lld s\n",
                   static_cast<long long>(kSaveAfterLostDisplay.count()));
    }
  }
  log_stop("display_lost");
}

// The condition of the next trial, as the session folder names it.
std::string TrainerApp::condition_name() const {
  if (options_.quiz) return kQuizCondition;
  if (!guidance_ || !condition_outputs_force_) return kVisionCondition;
  switch (guidance_mode_) {
    case GuidanceMode::fading:
      return kFadingCondition;
    case GuidanceMode::replay:
      return kReplayCondition;
    case GuidanceMode::assist_as_needed:
      return kAssistCondition;
    case GuidanceMode::error_amplification:
      return kAmplificationCondition;
    case GuidanceMode::timing:
      return kTimingCondition;
    case GuidanceMode::fixed:
      break;
  }
  return kHapticCondition;
}

std::span<const std::string> TrainerApp::characters_utf8(const TrialView& view) const {
  return {&options_.characters[view.character].utf8, 1};  // a practice trial's scene: its one character
}

const TrialView* TrainerApp::trial_view() const {
  if (session_) return session_->view();
  return view_ ? &*view_ : nullptr;
}

void TrainerApp::follow_session() {
  session_->follow(quiz_log_, [this](const std::vector<std::size_t>& characters) { show_row(characters); });
}

// A session's trial: the row becomes its characters.
void TrainerApp::show_row(const std::vector<std::size_t>& characters) {
  art_.clear();
  for (const std::size_t k : characters) art_.push_back(every_character_art_[k]);
  layout_.emplace(art_.size(), options_.width_px, options_.height_px, kPanelWidthPx);
  for (std::size_t k = 0; k < layout_->count(); ++k) {
    const ScreenBox& b = layout_->box(k);
    std::printf("box %zu %s x=%.0f y=%.0f size=%.0f\n", k, options_.characters[characters[k]].utf8.c_str(),
                b.x_px, b.y_px, b.size_px);
  }
  std::fflush(stdout);
}

bool TrainerApp::unattended() const { return options_.exit_after_s > 0.0; }

// ---- The loop.
void TrainerApp::loop() {
  auto next_frame = Clock::now();
  while (true) {
    glfwPollEvents();
    const bool closed = glfwWindowShouldClose(window_) != 0 || x11_error_seen();
    if (closed || StopSignals::received() != 0) quit_ = true;
    if (unattended() && seconds_since_start() >= options_.exit_after_s) quit_ = true;
    handle_keys();
    if (quit_ && !quit_seen_) {  // the picture at exit shows the window as it was when the exit came
      if (!options_.screenshot.empty() && !screenshot_taken_ && !x11_error_seen() && trial_view())
        render(true);
      quit_seen_ = true;
    }
    if (session_) {
      if (quit_) session_->request_stop();
      follow_session();
      if (session_->finished() && (quit_ || unattended())) break;
    }
    if (quit_ && worker_.active() && !worker_.done()) worker_.request_stop();
    if (pending_ != NextAction::none && worker_.active() && !worker_.done()) worker_.request_stop();
    if (view_ && worker_.active()) {
      view_->consume(*channel_, typical_ids_[view_->character]);
      quiz_log_.log_verdicts(*view_, characters_utf8(*view_));
      quiz_log_.log_refusal(*view_, characters_utf8(*view_));
      // The quiz asks for every stroke in order, judged its own way: once each is accepted the trial has
      // done its job and ends (saved as completed, see finish_trial), whatever the renderer counted.
      if (view_->quiz && view_->quiz->complete() && !worker_.done()) worker_.request_stop();
    }
    if (worker_.active() && worker_.done()) finish_trial();
    if (!worker_.active() && !session_) {
      if (quit_) break;
      if (pending_ == NextAction::repeat) start_trial(view_->character);
      if (pending_ == NextAction::next) start_trial((view_->character + 1) % options_.characters.size());
      pending_ = NextAction::none;
      if (advance_at_ && Clock::now() >= *advance_at_) start_trial(view_->character + 1);
    }
    update_pointer();
    if (x11_error_seen()) continue;  // the window is gone: no drawing, only the ending above
    // After the last character's trial, or the last planned trial's outcome.
    const bool screenshot_due = screenshot_due_ || (session_ && session_->last_trial_ended());
    const bool take_screenshot = !options_.screenshot.empty() && !screenshot_taken_ && screenshot_due;
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

double TrainerApp::seconds_since_start() const {
  return std::chrono::duration<double>(Clock::now() - started_).count();
}

void TrainerApp::handle_keys() {
  for (const int key : keys_) {
    switch (key) {
      case GLFW_KEY_Q:
      case GLFW_KEY_ESCAPE:
        quit_ = true;
        break;
      case GLFW_KEY_SPACE:
        if (session_) session_->start_trial();
        break;
      case GLFW_KEY_R:
        if (!session_) pending_ = NextAction::repeat;
        break;
      case GLFW_KEY_N:
        if (!session_) pending_ = NextAction::next;
        break;
      case GLFW_KEY_G:  // a quiz has no guidance
        if (!session_ && !options_.quiz) guidance_ = !guidance_;
        break;
      case GLFW_KEY_M:  // the guidance mode of the next trial, in turn (replay only with a teacher)
        if (!session_ && !options_.quiz) {
          const std::span<const GuidanceMode> modes = guidance_modes();
          auto at = std::find(modes.begin(), modes.end(), guidance_mode_);
          do {
            at = std::next(at) == modes.end() ? modes.begin() : std::next(at);
          } while (*at == GuidanceMode::replay && options_.teacher.empty());
          guidance_mode_ = *at;
        }
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

}  // namespace calligraphy::trainer
