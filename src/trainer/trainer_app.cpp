// The trainer's window loop (trainer.hpp): the window thread draws at the display rate from the
// display channel's snapshot and queues, never waiting on the servo thread; each trial runs on a worker
// thread through run_trial with real-time pacing, the ServoLoop on its own thread.
#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/report/teacher_recording.hpp"
#include "calligraphy/sim/hand_port.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "core/stop_signals.hpp"
#include "study/names.hpp"
#include "study/trial_record.hpp"
#include "trainer/layout.hpp"
#include "trainer/panel.hpp"
#include "trainer/pointer_devices.hpp"
#include "trainer/practice_session.hpp"
#include "trainer/scene_view.hpp"
#include "trainer/screenshot.hpp"
#include "trainer/session_host.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"
#include "trainer/trial_worker.hpp"
#include "trainer/x11_errors.hpp"

namespace calligraphy::trainer {
namespace {

constexpr double kPanelWidthPx = 400.0;
constexpr double kFramePeriodS = 1.0 / 60.0;
constexpr double kAdvanceDelayS = 1.0;  // unattended: pause on a trial's summary before the next
constexpr const char* kChineseFont = "/usr/share/fonts/truetype/arphic/ukai.ttc";

using Clock = std::chrono::steady_clock;

void print_glfw_error(int code, const char* description) {
  std::fprintf(stderr, "calligraphy train: GLFW error %d: %s\n", code, description);
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, k == 0 ? 0 : k - 1)];
}

// Keys pressed since the last frame (GLFW's key callback, on the window thread).
std::vector<int>* pending_keys = nullptr;
void record_key(GLFWwindow* /*window*/, int key, int /*scancode*/, int action, int /*mods*/) {
  if (action == GLFW_PRESS && pending_keys != nullptr) pending_keys->push_back(key);
}

enum class NextAction { none, repeat, next, quit };

// A study session the window hosts (run_trainer_session): the host and whether its thread is done.
struct SessionLink {
  WindowSessionHost* host = nullptr;
  const std::atomic<bool>* done = nullptr;
  const SessionManifest* manifest = nullptr;
};

const char* mode_meaning(ConditionMode mode) {
  switch (mode) {
    case ConditionMode::vision:
      return "vision only: no guiding force";
    case ConditionMode::haptic:
      return "with the guiding force";
    case ConditionMode::quiz:
      return "quiz: each stroke judged as the pen lifts";
    case ConditionMode::fading:
      return "fading guidance";
    case ConditionMode::replay:
      return "the teacher's movement replayed";
  }
  return "";
}

class TrainerApp {
 public:
  TrainerApp(const TrainerOptions& options, DeviceInfo device_info, bool hardware,
             const SessionLink* session = nullptr)
      : options_(options), device_info_(std::move(device_info)), hardware_(hardware), session_(session) {
    for (const TrainerCharacter& c : options.characters) {
      art_.push_back(prepare_art(c));
      std::vector<int> ids;
      for (const Stroke& s : c.model.strokes) ids.push_back(s.typical_id);
      typical_ids_.push_back(std::move(ids));
    }
    guidance_ = options.guidance && !options.quiz;  // a quiz is force-free but for the paper
    guidance_mode_ = options.guidance_mode;
    guidance_gain_ = options.guidance_gain;
    condition_outputs_force_ = options.device != "mouse";
    if (session_ != nullptr) {
      all_art_ = art_;
      all_typical_ids_ = typical_ids_;
      for (std::size_t k = 0; k < options.characters.size(); ++k)
        index_of_[options.characters[k].model.code_point] = k;
    }
  }

  int run() {
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
    open_window();
    layout_.emplace(session_ ? 1 : options_.characters.size(), options_.width_px, options_.height_px,
                    kPanelWidthPx);
    if (session_) art_.resize(1);
    for (std::size_t k = 0; k < layout_->count() && session_ == nullptr; ++k) {
      const ScreenBox& b = layout_->box(k);
      std::printf("box %zu %s x=%.0f y=%.0f size=%.0f\n", k, options_.characters[k].utf8.c_str(), b.x_px,
                  b.y_px, b.size_px);
    }
    std::fflush(stdout);
    started_ = Clock::now();
    if (session_ == nullptr) start_trial(0);
    loop();
    close_window();
    print_measurements();
    return status_;
  }

 private:
  void open_window() {
    glfwSetErrorCallback(print_glfw_error);
    if (glfwInit() == GLFW_FALSE) {
      throw Error("cannot open a window: GLFW could not initialise (no X display? DISPLAY is '" +
                  std::string(std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "") + "'; try xvfb-run)");
    }
    install_x11_error_handler();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    std::string title = "calligraphy train";
    for (const TrainerCharacter& c : options_.characters) title += " " + c.utf8;
    window_ = glfwCreateWindow(options_.width_px, options_.height_px, title.c_str(), nullptr, nullptr);
    if (window_ == nullptr) {
      glfwTerminate();
      throw Error("cannot open a window of " + std::to_string(options_.width_px) + "x" +
                  std::to_string(options_.height_px) + " with OpenGL 3.3 core");
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(1);
    pending_keys = &keys_;
    glfwSetKeyCallback(window_, record_key);  // before ImGui's, which calls it in turn
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    ImGui::StyleColorsLight();
    load_fonts();
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
  }

  void load_fonts() {
    ImGuiIO& io = ImGui::GetIO();
    if (!std::filesystem::exists(kChineseFont)) {
      std::fprintf(stderr,
                   "calligraphy train: %s not found (Debian fonts-arphic-ukai): characters show as '?'\n",
                   kChineseFont);
      return;
    }
    ImFontGlyphRangesBuilder builder;
    builder.AddRanges(io.Fonts->GetGlyphRangesDefault());
    for (const TrainerCharacter& c : options_.characters) builder.AddText(c.utf8.c_str());
    builder.BuildRanges(&glyph_ranges_);
    ImFontConfig config;
    config.FontNo = 0;
    io.Fonts->AddFontFromFileTTF(kChineseFont, 20.0f, &config, glyph_ranges_.Data);
    large_font_ = io.Fonts->AddFontFromFileTTF(kChineseFont, 34.0f, &config, glyph_ranges_.Data);
  }

  void close_window() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    if (!x11_error_seen()) glfwDestroyWindow(window_);
    glfwTerminate();
    pending_keys = nullptr;
  }

  // ---- Trials.
  void start_trial(std::size_t character) {
    std::vector<Character> one{options_.characters[character].model};
    Scene scene = Scene::lay_out(one);  // at the device's centre; the row shows it at its place
    channel_ = std::make_unique<DisplayChannel>();
    view_.emplace();
    view_->character = character;
    view_->number = ++trials_started_;
    view_->guidance = guidance_;
    view_->condition = condition_name();
    TrialOptions trial;
    trial.force.guidance = guidance_;
    trial.force.guidance_mode = guidance_mode_;
    trial.force.guidance_gain = guidance_gain_;
    if (guidance_mode_ == GuidanceMode::replay) trial.force.teacher_trajectory = options_.teacher;
    trial.pacing = TrialPacing::real_time;
    // A window process maps memory all the time (the GL driver): mlockall(MCL_FUTURE) would lock all of
    // it, or make its allocations fail under a memory-lock limit. The trace is touched in advance instead.
    trial.loop.lock_memory = false;
    trial.keep_trace = true;
    trial.simulation.writer =
        options_.writer_profile == "skilled" ? WriterProfile::skilled() : WriterProfile::novice();
    trial.simulation.seed = options_.seed + trials_started_ - 1;
    trial.display = channel_.get();
    trial_start_utc_ = study_detail::utc_now_iso8601();
    trial_wall_start_ = Clock::now();
    trial_options_ = trial;
    trial_options_.display = nullptr;
    worker_.start(std::move(scene), options_.device, std::move(trial));
    if (options_.quiz) view_->quiz.emplace(worker_.scene(), options_.quiz_options);
    advance_at_.reset();
  }

  // The worker is done: takes its result, saves it, and shows the summary.
  void finish_trial() {
    TrialView& view = *view_;
    TrialResult result;
    try {
      result = worker_.take();
    } catch (const std::exception& e) {
      view.have_result = true;
      view.ended = true;
      view.end = TrialEnd::device_fault;
      view.end_reason = e.what();
      std::fprintf(stderr, "calligraphy train: the trial could not run: %s\n", e.what());
      status_ = 1;
      quit_ = true;  // nothing to retry with the same device
      return;
    }
    view.consume(*channel_, typical_ids_[view.character]);
    log_quiz(view);
    if (view.quiz) check_quiz_against_trace(*view.quiz, result);
    view.have_result = true;
    view.ended = true;
    view.end = result.end;
    view.metrics = result.metrics;
    view.end_reason = result.abort_reason;
    if (result.end == TrialEnd::device_fault || result.end == TrialEnd::watchdog) status_ = 1;
    if (guidance_ && trial_options_.force.guidance_mode == GuidanceMode::fading &&
        result.metrics.mean_deviation_m) {  // performance-based fading (Emken et al. 2007)
      guidance_gain_ = next_guidance_gain(guidance_gain_, *result.metrics.mean_deviation_m);
      std::fprintf(stderr, "calligraphy train: fading: next trial's guidance gain %.3f\n", guidance_gain_);
    }
    if (!options_.record.empty() && result.end == TrialEnd::completed) save_recording(view, result);
    const std::string& utf8 = options_.characters[view.character].utf8;
    std::fprintf(stderr,
                 "calligraphy train: trial %zu %s: %s, %zu/%zu strokes in order, mean %.2f mm, %.1f s\n",
                 view.number, utf8.c_str(), to_string(result.end), result.metrics.strokes_completed,
                 result.metrics.strokes_total, result.metrics.mean_deviation_m.value_or(std::nan("")) * 1e3,
                 result.metrics.time_s);
    if (result.loop) {
      const ServoLoopStats& loop = *result.loop;
      std::fprintf(
          stderr,
          "calligraphy train: servo loop: %llu ticks, %llu late, %llu forces withheld, period jitter "
          "p50 %.1f us, p99 %.1f us, max %.1f us, longest stall %.2f ms\n",
          static_cast<unsigned long long>(loop.ticks), static_cast<unsigned long long>(loop.late_ticks),
          static_cast<unsigned long long>(loop.forces_withheld), loop.period_jitter_us_p50,
          loop.period_jitter_us_p99, loop.period_jitter_us_max, loop.longest_stall_s * 1e3);
    }
    if (practice_) {
      PracticeTrial trial;
      trial.item = view.character;
      trial.character = options_.characters[view.character].model.code_point;
      trial.condition = view.condition;
      trial.scene = &worker_.scene();
      trial.options = &trial_options_;
      trial.start_utc = trial_start_utc_;
      trial.end_utc = study_detail::utc_now_iso8601();
      trial.wall_time_s = std::chrono::duration<double>(Clock::now() - trial_wall_start_).count();
      try {
        const auto [path, as_trial] = practice_->save(trial, result);
        view.saved_as = (as_trial ? "" : "attempts/") + path.filename().string();
        std::fprintf(stderr, "calligraphy train: saved %s (%s)\n", path.c_str(),
                     as_trial ? "the trial, .csv, .svg" : "an attempt, .csv");
      } catch (const std::exception& e) {
        view.save_error = std::string("not saved: ") + e.what();
        std::fprintf(stderr, "calligraphy train: error: the trial was not saved: %s\n", e.what());
        status_ = 1;
      }
    }
    const bool last = view.character + 1 == options_.characters.size();
    if (last) screenshot_due_ = true;  // after the last character's last stroke
    if (unattended()) {
      if (last) {
        quit_ = true;
      } else {
        advance_at_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(kAdvanceDelayS));
      }
    }
  }

  // ---- A study session (run_trainer_session): the window follows the session thread's host.
  void follow_session() {
    session_view_ = session_->host->view();
    const SessionView& s = session_view_;
    if (s.phase != SessionPhase::waiting && s.trial_generation != shown_generation_) {
      shown_generation_ = s.trial_generation;
      show_session_trial(s);
    }
    if (!view_ || s.trial_generation != shown_generation_) return;
    if (s.channel && s.channel != session_channel_) session_channel_ = s.channel;
    if (session_channel_) view_->consume(*session_channel_, typical_ids_.front());
    log_quiz(*view_);
    if (s.outcome && !view_->have_result) {
      view_->have_result = true;
      view_->ended = true;
      view_->metrics.time_s = s.outcome->time_s;
      view_->metrics.strokes_completed = view_->snapshot.strokes_completed;
      view_->metrics.strokes_total = view_->snapshot.strokes_total;
      if (std::isfinite(s.outcome->mean_deviation_mm))
        view_->metrics.mean_deviation_m = s.outcome->mean_deviation_mm * 1e-3;
      double max_m = 0.0;
      for (const StrokeResult& r : view_->results) max_m = std::max(max_m, r.max_deviation_m);
      if (!view_->results.empty()) view_->metrics.max_deviation_m = max_m;
      const std::filesystem::path file(s.outcome->json_file);
      view_->saved_as = s.outcome->saved ? file.filename().string() : "";
      if (!s.outcome->saved) view_->end_reason = "kept as an attempt: " + file.filename().string();
      std::fprintf(stderr, "calligraphy session: trial %zu/%zu %s: %s, %.1f s, mean %.2f mm%s\n",
                   s.trial.index + 1, s.total, s.trial.condition.c_str(), s.outcome->end_reason.c_str(),
                   s.outcome->time_s, s.outcome->mean_deviation_mm, s.outcome->saved ? "" : " (attempt)");
      if (s.trial.index + 1 == s.total) screenshot_due_ = true;  // the last planned trial's outcome
    }
  }

  // A new trial: the row becomes its characters, the view a fresh one.
  void show_session_trial(const SessionView& s) {
    art_.clear();
    typical_ids_.clear();
    for (const char32_t c : s.trial.characters) {
      const std::size_t k = index_of_.at(c);
      art_.push_back(all_art_[k]);
      typical_ids_.push_back(all_typical_ids_[k]);
    }
    // Stroke events count strokes within their character; a one-character trial (the usual) names its own.
    layout_.emplace(art_.size(), options_.width_px, options_.height_px, kPanelWidthPx);
    for (std::size_t k = 0; k < layout_->count(); ++k) {
      const ScreenBox& b = layout_->box(k);
      std::printf("box %zu %s x=%.0f y=%.0f size=%.0f\n", k,
                  options_.characters[index_of_.at(s.trial.characters[k])].utf8.c_str(), b.x_px, b.y_px,
                  b.size_px);
    }
    std::fflush(stdout);
    view_.emplace();
    view_->whole_row = true;
    view_->number = s.trial.index + 1;
    view_->guidance = s.guidance;
    view_->condition = s.trial.condition;
    session_channel_.reset();
    session_scene_ = session_scene(s.trial);
    if (s.mode == ConditionMode::quiz) {
      view_->quiz.emplace(session_scene_,
                          session_->manifest->protocol.protocol.condition(s.trial.condition).quiz);
    }
  }

  Scene session_scene(const PlannedTrial& trial) const {
    std::vector<Character> models;
    for (const char32_t c : trial.characters) models.push_back(options_.characters[index_of_.at(c)].model);
    return Scene::lay_out(models);
  }

  void session_panel(PanelInput& panel) const {
    const SessionView& s = session_view_;
    const SessionSetup& setup = session_->manifest->setup;
    std::string characters;
    for (const char32_t c : s.trial.characters) characters += options_.characters[index_of_.at(c)].utf8;
    panel.character = characters;
    char line[256];
    std::snprintf(line, sizeof line, "Session %s, subject %s\ntrial %zu of %zu (%s), condition %s: %s",
                  session_->manifest->protocol.protocol.name.c_str(), setup.subject.id.c_str(),
                  s.trial.index + 1, s.total, to_string(s.trial.phase), s.trial.condition.c_str(),
                  mode_meaning(s.mode));
    panel.session = s.phase == SessionPhase::waiting ? "Session " + session_->manifest->session_id : line;
    switch (s.phase) {
      case SessionPhase::waiting:
        panel.prompt = "starting...";
        break;
      case SessionPhase::announced:
        panel.prompt = "Next: write " + characters + (unattended() ? "" : "\npress Space to start");
        break;
      case SessionPhase::resting: {
        const double left = std::chrono::duration<double>(s.rest_until - Clock::now()).count();
        char rest[64];
        std::snprintf(rest, sizeof rest, "Rest: %.0f s", std::max(0.0, std::ceil(left)));
        panel.prompt = rest;
        break;
      }
      case SessionPhase::running:
        panel.prompt = "Write " + characters;
        break;
      case SessionPhase::outcome:
        panel.prompt = s.outcome && s.outcome->saved ? "Trial saved" : "Trial kept as an attempt";
        break;
      case SessionPhase::finished:
        panel.prompt = "Session over" + std::string(unattended() ? "" : "\nEsc closes the window");
        break;
    }
    panel.characters = s.trial.characters.size();
  }

  // The last completed trial as a teacher's recording (replay guidance), replaced atomically.
  void save_recording(TrialView& view, const TrialResult& result) {
    try {
      const TeacherRecording recording =
          teacher_recording_from_trace(options_.characters[view.character].utf8,
                                       options_.simulated_writer ? options_.writer_profile : "human",
                                       options_.device, trial_options_.rate_hz, result.trace);
      write_file_atomically(options_.record, teacher_recording_json(recording));
      std::fprintf(stderr, "calligraphy train: teacher recording %s (%zu samples)\n", options_.record.c_str(),
                   recording.samples.size());
    } catch (const std::exception& e) {
      view.save_error += std::string(" recording not written: ") + e.what();
      std::fprintf(stderr, "calligraphy train: error: the recording was not written: %s\n", e.what());
      status_ = 1;
    }
  }

  // The quiz's new verdicts: one stderr line each (the test harness and logs read them), and a screenshot
  // of the frame that first shows a judged stroke when asked.
  void log_quiz(TrialView& view) {
    if (!view.quiz) return;
    const char* who = session_ ? "calligraphy session" : "calligraphy train";
    for (const auto& [character, event] : view.quiz_unlogged) {
      const std::string utf8 = character_utf8(view, character);
      std::fprintf(stderr, "%s: quiz %s %s\n", who, utf8.c_str(), describe(event).c_str());
      if (event.kind == QuizEvent::Kind::character_completed) {
        std::fprintf(stderr, "%s: quiz %s complete, %d misses\n", who, utf8.c_str(), event.total_misses);
      }
      const bool judged = event.kind == QuizEvent::Kind::stroke_accepted ||
                          event.kind == QuizEvent::Kind::stroke_missed ||
                          event.kind == QuizEvent::Kind::too_short;
      if (judged && !options_.quiz_screenshots.empty()) {
        char name[64];
        std::snprintf(name, sizeof name, "quiz-%02zu-%s.png", ++quiz_verdicts_, to_string(event.kind));
        quiz_screenshot_ = (std::filesystem::path(options_.quiz_screenshots) / name).string();
      }
    }
    view.quiz_unlogged.clear();
  }

  [[nodiscard]] std::string character_utf8(const TrialView& view, std::size_t character) const {
    if (session_ == nullptr) return options_.characters[view.character].utf8;
    const char32_t c = session_view_.trial.characters.at(character);
    return options_.characters[index_of_.at(c)].utf8;
  }

  // The saved record judges the whole trace after the trial (study_detail::quiz_characters): the verdicts
  // shown live must be the same ones.
  void check_quiz_against_trace(const LiveQuiz& quiz, const TrialResult& result) {
    const std::vector<std::vector<QuizEvent>> saved =
        study_detail::quiz_characters(worker_.scene(), result.trace, options_.quiz_options);
    const std::vector<std::vector<QuizEvent>> live = quiz.events();
    bool same = saved.size() == live.size();
    std::size_t count = 0;
    for (std::size_t c = 0; same && c < saved.size(); ++c) {
      same = saved[c].size() == live[c].size();
      for (std::size_t k = 0; same && k < saved[c].size(); ++k) {
        const QuizEvent& a = saved[c][k];
        const QuizEvent& b = live[c][k];
        same = a.kind == b.kind && a.stroke == b.stroke && a.backwards == b.backwards &&
               a.misses_on_stroke == b.misses_on_stroke && a.total_misses == b.total_misses &&
               a.time_s == b.time_s && a.samples == b.samples &&
               a.closer_later_stroke == b.closer_later_stroke;
        ++count;
      }
    }
    if (same) {
      std::fprintf(stderr, "calligraphy train: quiz: the %zu live verdicts are the saved record's\n", count);
    } else {
      std::fprintf(
          stderr,
          "calligraphy train: warning: quiz: the live verdicts differ from the saved record's, which "
          "judges the whole trace (%llu trace points did not reach the window)\n",
          static_cast<unsigned long long>(quiz.dropped_points()));
    }
  }

  // The condition of the next trial, as the session folder names it.
  [[nodiscard]] std::string condition_name() const {
    if (options_.quiz) return kQuizCondition;
    if (!guidance_ || !condition_outputs_force_) return kVisionCondition;
    switch (guidance_mode_) {
      case GuidanceMode::fading:
        return kFadingCondition;
      case GuidanceMode::replay:
        return kReplayCondition;
      case GuidanceMode::fixed:
        break;
    }
    return kHapticCondition;
  }

  [[nodiscard]] bool unattended() const { return options_.exit_after_s > 0.0; }

  // ---- The loop.
  void loop() {
    auto next_frame = Clock::now();
    while (true) {
      glfwPollEvents();
      const bool closed = glfwWindowShouldClose(window_) != 0 || x11_error_seen();
      if (closed || StopSignals::received() != 0) quit_ = true;
      if (unattended() && seconds_since_start() >= options_.exit_after_s) quit_ = true;
      handle_keys();
      if (quit_ && !quit_seen_) {  // the picture at exit shows the window as it was when the exit came
        if (!options_.screenshot.empty() && !screenshot_taken_ && !x11_error_seen() && view_) render(true);
        quit_seen_ = true;
      }
      if (session_ != nullptr) {
        if (quit_) session_->host->request_stop();
        follow_session();
        if (session_->done->load() && (quit_ || unattended())) break;
      }
      if (quit_ && worker_.active() && !worker_.done()) worker_.request_stop();
      if (pending_ != NextAction::none && worker_.active() && !worker_.done()) worker_.request_stop();
      if (view_ && worker_.active()) {
        view_->consume(*channel_, typical_ids_[view_->character]);
        log_quiz(*view_);
      }
      if (worker_.active() && worker_.done()) finish_trial();
      if (!worker_.active() && session_ == nullptr) {
        if (quit_) break;
        if (pending_ == NextAction::repeat) start_trial(view_->character);
        if (pending_ == NextAction::next) start_trial((view_->character + 1) % options_.characters.size());
        pending_ = NextAction::none;
        if (advance_at_ && Clock::now() >= *advance_at_) start_trial(view_->character + 1);
      }
      update_pointer();
      if (x11_error_seen()) continue;  // the window is gone: no drawing, only the ending above
      const bool take_screenshot = !options_.screenshot.empty() && !screenshot_taken_ && screenshot_due_;
      render(take_screenshot);
      next_frame += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kFramePeriodS));
      if (next_frame < Clock::now()) next_frame = Clock::now();
      std::this_thread::sleep_until(next_frame);
    }
    // The last character's trial ended in this very iteration: its summary, after the last stroke.
    if (!options_.screenshot.empty() && !screenshot_taken_ && !x11_error_seen() && view_) render(true);
    // A stroke judged as the trial ended (the pen still down): the frame that shows it.
    if (!quiz_screenshot_.empty() && !x11_error_seen() && view_) render(false);
  }

  double seconds_since_start() const {
    return std::chrono::duration<double>(Clock::now() - started_).count();
  }

  void handle_keys() {
    for (const int key : keys_) {
      switch (key) {
        case GLFW_KEY_Q:
        case GLFW_KEY_ESCAPE:
          quit_ = true;
          break;
        case GLFW_KEY_SPACE:
          if (session_ != nullptr) session_->host->start_trial();
          break;
        case GLFW_KEY_R:
          if (session_ == nullptr) pending_ = NextAction::repeat;
          break;
        case GLFW_KEY_N:
          if (session_ == nullptr) pending_ = NextAction::next;
          break;
        case GLFW_KEY_G:  // a quiz has no guidance
          if (session_ == nullptr && !options_.quiz) guidance_ = !guidance_;
          break;
        case GLFW_KEY_M:  // the guidance mode of the next trial: fixed, fading, replay (with a teacher)
          if (session_ == nullptr && !options_.quiz) {
            guidance_mode_ = guidance_mode_ == GuidanceMode::fixed ? GuidanceMode::fading
                             : guidance_mode_ == GuidanceMode::fading && !options_.teacher.empty()
                                 ? GuidanceMode::replay
                                 : GuidanceMode::fixed;
          }
          break;
        default:
          break;
      }
    }
    keys_.clear();
  }

  // The pointer in the running trial's metres, for the mouse devices (lock-free; read by the servo thread).
  void update_pointer() {
    if (!view_ || !layout_) return;
    double x = 0.0;
    double y = 0.0;
    glfwGetCursorPos(window_, &x, &y);
    const bool in_area = x >= 0.0 && x < layout_->area_width_px() && y >= 0.0 && y < layout_->height_px();
    const bool pressed = in_area && glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const Vec2 trial_m = view_->whole_row ? layout_->screen_to_row(Vec2(x, y))
                                          : layout_->to_trial(view_->character, Vec2(x, y));
    pointer_input().set(trial_m.x(), trial_m.y(), pressed);
  }

  void render(bool take_screenshot) {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const Scene& scene = session_ ? session_scene_ : worker_.scene();
    draw_scene(*ImGui::GetBackgroundDrawList(), *layout_, art_, scene, view_ ? &*view_ : nullptr);
    PanelInput panel;
    panel.view = view_ ? &*view_ : nullptr;
    if (view_ && session_ == nullptr) panel.character = options_.characters[view_->character].utf8;
    if (session_ != nullptr) session_panel(panel);
    panel.device = options_.device;
    panel.characters = options_.characters.size();
    panel.next_guidance = guidance_;
    panel.quiz = options_.quiz;
    panel.next_mode = to_string(guidance_mode_);
    panel.next_gain = guidance_gain_;
    panel.unattended = unattended();
    panel.frame_rate_hz = ImGui::GetIO().Framerate;
    panel.large_font = large_font_;
    if (quit_seen_ && worker_.active() && !worker_.done()) panel.status = "ending the trial...";
    draw_panel(*layout_, kPanelWidthPx, panel);
    ImGui::Render();
    int width = 0;
    int height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    glViewport(0, 0, width, height);
    glClearColor(1.0f, 1.0f, 1.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (!quiz_screenshot_.empty()) {  // the first frame that shows the latest judged stroke
      try {
        write_framebuffer_png(quiz_screenshot_, width, height);
        std::fprintf(stderr, "calligraphy train: quiz screenshot %s\n", quiz_screenshot_.c_str());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "calligraphy train: error: %s\n", e.what());
        status_ = 1;
      }
      quiz_screenshot_.clear();
    }
    if (take_screenshot) {
      try {
        write_framebuffer_png(options_.screenshot, width, height);
        std::fprintf(stderr, "calligraphy train: screenshot %s\n", options_.screenshot.c_str());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "calligraphy train: error: %s\n", e.what());
        status_ = 1;
      }
      screenshot_taken_ = true;
    }
    glfwSwapBuffers(window_);
    ++frames_;
    // Display latency: from the servo tick that published the snapshot to the frame that shows it.
    const bool live = (worker_.active() && !worker_.done()) ||
                      (session_ != nullptr && session_view_.phase == SessionPhase::running);
    if (view_ && live && view_->snapshot.tick > 0) {
      latencies_ms_.push_back(static_cast<double>(steady_ns() - view_->snapshot.published_ns) * 1e-6);
    }
  }

  void print_measurements() const {
    const double seconds = seconds_since_start();
    std::fprintf(
        stderr,
        "calligraphy train: %zu frames in %.1f s (%.1f frames/s); display latency, servo tick to frame "
        "shown: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %zu frames\n",
        frames_, seconds, static_cast<double>(frames_) / std::max(seconds, 1e-9),
        percentile(latencies_ms_, 0.5), percentile(latencies_ms_, 0.99), percentile(latencies_ms_, 1.0),
        latencies_ms_.size());
  }

  TrainerOptions options_;
  DeviceInfo device_info_;
  bool hardware_ = false;
  std::optional<PracticeSession> practice_;
  const SessionLink* session_ = nullptr;
  SessionView session_view_;
  std::uint64_t shown_generation_ = 0;
  std::shared_ptr<DisplayChannel> session_channel_;
  Scene session_scene_;
  std::vector<CharacterArt> all_art_;
  std::vector<std::vector<int>> all_typical_ids_;
  std::map<char32_t, std::size_t> index_of_;
  TrialOptions trial_options_;
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
  bool condition_outputs_force_ = true;
  bool quit_ = false;
  bool quit_seen_ = false;
  NextAction pending_ = NextAction::none;
  std::optional<Clock::time_point> advance_at_;
  bool screenshot_due_ = false;
  std::size_t quiz_verdicts_ = 0;
  std::string quiz_screenshot_;  // written at the next frame
  bool screenshot_taken_ = false;
  Clock::time_point started_;
  std::size_t frames_ = 0;
  std::vector<double> latencies_ms_;
  int status_ = 0;
};

}  // namespace

int run_trainer(const TrainerOptions& options) {
  if (options.characters.empty()) throw InvalidArgument("calligraphy train: no characters to practise");
  // The device must exist, and a simulated writer can move only a device with a hand port.
  const std::unique_ptr<HapticDevice> probe = device_registry_with_simulation().create(options.device);
  const bool hand_port = dynamic_cast<HandPort*>(probe.get()) != nullptr;
  if (options.simulated_writer && !hand_port) {
    throw InvalidArgument(
        "--writer simulated needs a device a simulated writer can move (simulated, "
        "emulated-phantom); '" +
        options.device + "' is moved by a person");
  }
  if (!options.simulated_writer && hand_port) {
    throw InvalidArgument("device '" + options.device +
                          "' is moved by the simulated writer: pass --writer simulated, or use mouse, "
                          "mouse-hand or a haptic device");
  }
  // SIGINT, SIGTERM and SIGHUP only set a flag; the window loop ends the trial safely. A command that
  // installed the handlers already (a study session) keeps them.
  std::optional<StopSignals> signals;
  if (!StopSignals::installed()) signals.emplace();
  bool hardware = false;
  for (const DeviceListing& listing : device_registry_with_simulation().survey().devices)
    hardware = hardware || (listing.name == options.device && listing.hardware);
  TrainerApp app(options, probe->info(), hardware);
  return app.run();
}

SessionRunResult run_trainer_session(const TrainerSessionOptions& options) {
  if (options.session == nullptr) throw InvalidArgument("run_trainer_session: no session");
  SessionFolder& folder = *options.session;
  const SessionManifest& manifest = folder.manifest();
  TrainerOptions window;
  std::map<char32_t, bool> seen;
  for (const PlannedTrial& trial : manifest.plan) {
    for (const char32_t c : trial.characters) {
      if (seen[c]) continue;
      seen[c] = true;
      window.characters.push_back(options.load_character(c));
    }
  }
  if (window.characters.empty()) throw InvalidArgument("run_trainer_session: the plan has no characters");
  window.device = manifest.setup.device;
  window.width_px = options.width_px;
  window.height_px = options.height_px;
  window.screenshot = options.screenshot;
  window.quiz_screenshots = options.quiz_screenshots;
  window.exit_after_s = options.exit_after_s;
  window.library_version = options.library_version;
  std::optional<StopSignals> signals;
  if (!StopSignals::installed()) signals.emplace();

  WindowSessionHost host(manifest, options.exit_after_s > 0.0, kAdvanceDelayS);
  SessionRunOptions run = options.run;
  run.host = &host;
  run.prepare_trial = [&host](const PlannedTrial& trial, TrialOptions& trial_options) {
    host.prepare_trial(trial, trial_options);
  };
  const std::function<bool()> outer_stop = options.run.should_stop;
  run.should_stop = [&host, outer_stop] {
    return host.stop_requested() || StopSignals::received() != 0 || (outer_stop && outer_stop());
  };
  std::atomic<bool> done{false};
  std::optional<SessionRunResult> result;
  std::exception_ptr failure;
  const SessionLink link{&host, &done, &manifest};
  TrainerApp app(window, DeviceInfo{}, false, &link);
  std::thread runner([&] {
    try {
      result = run_session(folder, run);
    } catch (...) {
      failure = std::current_exception();
    }
    host.mark_finished();
    done.store(true);
  });
  try {
    app.run();
  } catch (...) {
    host.request_stop();
    runner.join();
    throw;
  }
  host.request_stop();  // the window is closed: nothing more is shown
  runner.join();
  if (failure) std::rethrow_exception(failure);
  return *result;
}

void register_trainer_devices() { register_pointer_devices(device_registry_with_simulation()); }

}  // namespace calligraphy::trainer
