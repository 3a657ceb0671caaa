// A study session in the trainer's window (run_trainer_session): the session runs on its own thread, the
// window follows its host and shows each planned trial.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/stop_signals.hpp"
#include "trainer/trainer_app.hpp"

namespace calligraphy::trainer {
namespace {

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
    case ConditionMode::assist_as_needed:
      return "help only beyond a band around the stroke";
    case ConditionMode::error_amplification:
      return "errors enlarged by a gentle push off the stroke";
    case ConditionMode::skill_adaptive:
      return "help or error enlargement, by your last error";
    case ConditionMode::timing:
      return "a target that paces you along the stroke";
  }
  return "";
}

}  // namespace

// ---- A study session (run_trainer_session): the window follows the session thread's host.
void TrainerApp::follow_session() {
  session_view_ = session_->host->view();
  const SessionView& s = session_view_;
  if (s.phase != SessionPhase::waiting && s.trial_generation != shown_generation_) {
    shown_generation_ = s.trial_generation;
    show_session_trial(s);
  }
  if (!view_ || s.trial_generation != shown_generation_) return;
  if (s.channel && s.channel != session_channel_) {
    session_channel_ = s.channel;
    view_->scene = &session_scene_;  // laid out as the session runner lays out the trial's scene
    view_->acceptance = s.acceptance;
  }
  if (session_channel_) view_->consume(*session_channel_, typical_ids_.front());
  quiz_log_.log_verdicts(*view_, session_utf8_);
  quiz_log_.log_refusal(*view_, session_utf8_);
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
void TrainerApp::show_session_trial(const SessionView& s) {
  art_.clear();
  typical_ids_.clear();
  session_utf8_.clear();
  for (const char32_t c : s.trial.characters) {
    const std::size_t k = index_of_.at(c);
    art_.push_back(all_art_[k]);
    typical_ids_.push_back(all_typical_ids_[k]);
    session_utf8_.push_back(options_.characters[k].utf8);
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

Scene TrainerApp::session_scene(const PlannedTrial& trial) const {
  std::vector<Character> models;
  for (const char32_t c : trial.characters) models.push_back(options_.characters[index_of_.at(c)].model);
  return Scene::lay_out(models);
}

void TrainerApp::session_panel(PanelInput& panel) const {
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

}  // namespace calligraphy::trainer
