// The trainer's window (trainer_window.hpp): GLFW and Dear ImGui set up and torn down, the fonts, one frame
// drawn, screenshots, and the window's measurements (frame rate, display latency).
#include "trainer/trainer_window.hpp"

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "trainer/screenshot.hpp"
#include "trainer/trainer.hpp"
#include "trainer/x11_errors.hpp"

namespace calligraphy::trainer {
namespace {

constexpr const char* kChineseFont = "/usr/share/fonts/truetype/arphic/ukai.ttc";

// While the window is being opened, GLFW's error is kept for the one error line that says the window could
// not be opened (docs/cli.md: an error is one line); once it is open, each is a warning line of its own.
std::string* glfw_start_error = nullptr;

void print_glfw_error(int code, const char* description) {
  if (glfw_start_error != nullptr) {
    glfw_start_error->assign("GLFW error ").append(std::to_string(code)).append(": ").append(description);
    return;
  }
  std::fprintf(stderr, "calligraphy train: warning: GLFW error %d: %s\n", code, description);
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
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

// The size --window asked for: the layout, the printed boxes and the screenshot are for it. GLFW_RESIZABLE
// only asks a window manager to keep it; without one (Xvfb, or a client such as `xdotool windowsize`) the
// window can be resized all the same, so its size callback puts the asked size back.
int asked_width_px = 0;
int asked_height_px = 0;
void keep_asked_size(GLFWwindow* window, int width_px, int height_px) {
  if (asked_width_px > 0 && (width_px != asked_width_px || height_px != asked_height_px)) {
    glfwSetWindowSize(window, asked_width_px, asked_height_px);
  }
}

// "cannot open a window: GLFW could not initialise (no X display? ...)": the one line for a display that is
// not there, from open_window and check_display alike.
std::string no_display_message() {
  std::string message = "cannot open a window: GLFW could not initialise (no X display? DISPLAY is '";
  message.append(std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "").append("'; try xvfb-run)");
  return message;
}

}  // namespace

void check_display() {
  glfwSetErrorCallback(nullptr);  // the refusal below is the one line
  if (glfwInit() == GLFW_FALSE) throw Error(no_display_message());
  glfwTerminate();
}

void TrainerApp::open_window() {
  std::string start_error;
  struct KeptWhileOpening {
    explicit KeptWhileOpening(std::string* kept) { glfw_start_error = kept; }
    ~KeptWhileOpening() { glfw_start_error = nullptr; }
    KeptWhileOpening(const KeptWhileOpening&) = delete;
    KeptWhileOpening& operator=(const KeptWhileOpening&) = delete;
  } keep_errors(&start_error);
  glfwSetErrorCallback(print_glfw_error);
  const auto said = [&start_error] {
    std::string text;
    if (!start_error.empty()) text.append(" (").append(start_error).append(")");
    return text;
  };
  if (glfwInit() == GLFW_FALSE) throw Error(no_display_message() + said());
  install_x11_error_handler();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  std::string title = "calligraphy train";
  for (const TrainerCharacter& c : options_.characters) title += " " + c.utf8;
  window_ = glfwCreateWindow(options_.width_px, options_.height_px, title.c_str(), nullptr, nullptr);
  glfw_start_error = nullptr;  // open (or not): from here each GLFW error is a warning line
  if (window_ == nullptr) {
    glfwTerminate();
    throw Error("cannot open a window of " + std::to_string(options_.width_px) + "x" +
                std::to_string(options_.height_px) + " with OpenGL 3.3 core" + said());
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  pending_keys = &keys_;
  glfwSetKeyCallback(window_, record_key);  // before ImGui's, which calls it in turn
  asked_width_px = options_.width_px;
  asked_height_px = options_.height_px;
  glfwSetWindowSizeCallback(window_, keep_asked_size);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  ImGui::StyleColorsLight();
  load_fonts();
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
}

void TrainerApp::load_fonts() {
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

void TrainerApp::close_window() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  if (!x11_error_seen()) glfwDestroyWindow(window_);
  glfwTerminate();
  pending_keys = nullptr;
  asked_width_px = 0;
  asked_height_px = 0;
}

void TrainerApp::render(bool take_screenshot) {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  // A window destroyed by another client since the loop looked: GLFW's size query just failed (the X error
  // handler recorded it) and left the size undefined, which ImGui::NewFrame asserts on. Nothing to draw; the
  // loop ends the trial as after any X error.
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  if (x11_error_seen() || !(size.x >= 0.0f && size.y >= 0.0f)) return;
  ImGui::NewFrame();
  const Scene& scene = practice_ ? practice_->scene() : session_->scene();
  const TrialView* view = trial_view();
  const std::optional<DemoView> demo = practice_ ? practice_->demo_view() : std::nullopt;
  draw_scene(*ImGui::GetBackgroundDrawList(), *layout_, art_, scene, view, demo ? &*demo : nullptr,
             !options_.engineer);
  PanelInput panel;
  panel.view = view;
  panel.engineer = options_.engineer;
  panel.practice_buttons = practice_.has_value() && !unattended();
  if (demo)
    panel.demonstrating = std::make_pair(std::min(demo->frame.stroke + 1, demo->strokes), demo->strokes);
  if (practice_) practice_->fill_panel(panel);
  if (session_) session_->fill_panel(panel);
  panel.device = options_.device;
  panel.characters = options_.characters.size();
  panel.quiz = options_.quiz;
  panel.unattended = unattended();
  panel.frame_rate_hz = ImGui::GetIO().Framerate;
  panel.large_font = large_font_;
  if (demo) panel.character = options_.characters[demo->box].utf8;  // before its character's first trial
  panel.device_kind = learner_device_;
  panel.device_line = device_line(learner_device_, view != nullptr ? view->guidance : panel.next_guidance);
  if (quit_seen_ && practice_ && practice_->trial_running()) panel.status = "ending the trial...";
  // The panel's text of the picture at the end, for tests and tools (CALLIGRAPHY_PANEL_TEXT,
  // docs/trainer.md).
  const char* panel_text = std::getenv("CALLIGRAPHY_PANEL_TEXT");
  const bool log_panel = take_screenshot && panel_text != nullptr && *panel_text != '\0';
  if (log_panel) {
    std::remove(panel_text);
    ImGui::LogToFile(-1, panel_text);
  }
  const PanelAction action = draw_panel(*layout_, kPanelWidthPx, panel);
  if (log_panel) ImGui::LogFinish();
  if (action != PanelAction::none) action_ = action;
  ImGui::Render();
  int width = 0;
  int height = 0;
  glfwGetFramebufferSize(window_, &width, &height);
  glViewport(0, 0, width, height);
  glClearColor(1.0f, 1.0f, 1.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (quiz_log_.screenshot_requested()) {  // the first frame that shows the latest judged stroke
    const std::string quiz_screenshot = quiz_log_.take_screenshot_request();
    try {
      write_framebuffer_png(quiz_screenshot, width, height);
      std::fprintf(stderr, "calligraphy train: quiz screenshot %s\n", quiz_screenshot.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "calligraphy train: error: %s\n", e.what());
      screenshot_failed_ = true;
    }
  }
  if (take_screenshot) {
    try {
      write_framebuffer_png(options_.screenshot, width, height);
      std::fprintf(stderr, "calligraphy train: screenshot %s\n", options_.screenshot.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "calligraphy train: error: %s\n", e.what());
      screenshot_failed_ = true;
    }
    screenshot_taken_ = true;
  }
  glfwSwapBuffers(window_);
  ++frames_;
  // Display latency: from the servo tick that published the snapshot to the frame that shows it.
  const bool live = (practice_ && practice_->trial_running()) || (session_ && session_->trial_running());
  if (view != nullptr && live && view->snapshot.tick > 0) {
    latencies_ms_.push_back(static_cast<double>(steady_ns() - view->snapshot.published_ns) * 1e-6);
  }
}

void TrainerApp::print_measurements() const {
  const double seconds = seconds_since_start();
  std::fprintf(
      stderr,
      "calligraphy train: %zu frames in %.1f s (%.1f frames/s); display latency, servo tick to frame "
      "shown: p50 %.2f ms, p99 %.2f ms, max %.2f ms over %zu frames\n",
      frames_, seconds, static_cast<double>(frames_) / std::max(seconds, 1e-9),
      percentile(latencies_ms_, 0.5), percentile(latencies_ms_, 0.99), percentile(latencies_ms_, 1.0),
      latencies_ms_.size());
}

}  // namespace calligraphy::trainer
