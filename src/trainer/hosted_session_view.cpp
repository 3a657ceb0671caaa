// A study session in the trainer's window (hosted_session_view.hpp).
#include "trainer/hosted_session_view.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

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

HostedSessionView::HostedSessionView(const SessionLink& link, const std::vector<TrainerCharacter>& characters,
                                     bool unattended)
    : link_(link), characters_(characters), unattended_(unattended) {
  for (std::size_t k = 0; k < characters.size(); ++k) index_of_[characters[k].model.code_point] = k;
}

void HostedSessionView::follow(QuizLog& quiz_log,
                               const std::function<void(const std::vector<std::size_t>&)>& show_row) {
  state_ = link_.host->view();
  const SessionView& s = state_;
  if (s.phase != SessionPhase::waiting && s.trial_generation != shown_generation_) {
    shown_generation_ = s.trial_generation;
    show_trial(s, show_row);
  }
  if (!view_ || s.trial_generation != shown_generation_) return;
  if (s.channel && s.channel != channel_) {
    channel_ = s.channel;
    view_->scene = &scene_;  // laid out as the session runner lays out the trial's scene
    view_->acceptance = s.acceptance;
  }
  if (channel_) view_->consume(*channel_, shown_typical_ids_);
  quiz_log.log_verdicts(*view_, shown_utf8_);
  quiz_log.log_refusal(*view_, shown_utf8_);
  if (s.outcome && !view_->have_result) {
    view_->have_result = true;
    view_->ended = true;
    view_->metrics.time_s = std::isnan(s.outcome->time_s) ? 0.0 : s.outcome->time_s;  // nothing written: 0 s
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
    // A trial that wrote no stroke has no deviation (NaN in the outcome): said in words, not as "nan".
    char deviation[64] = "no stroke written";
    if (std::isfinite(s.outcome->mean_deviation_mm))
      std::snprintf(deviation, sizeof deviation, "mean deviation %.2f mm", s.outcome->mean_deviation_mm);
    // The writing time, first to last pen-down: none when the pen never touched.
    char time[48] = "the pen never touched";
    if (std::isfinite(s.outcome->time_s)) std::snprintf(time, sizeof time, "after %.1f s", s.outcome->time_s);
    std::fprintf(stderr, "calligraphy session: trial %zu/%zu %s: %s %s, %s; %s %s\n", s.trial.index + 1,
                 s.total, s.trial.condition.c_str(), s.outcome->end_reason.c_str(), time, deviation,
                 s.outcome->saved ? "saved as" : "kept as an attempt:", file.filename().c_str());
    if (s.trial.index + 1 == s.total) last_trial_ended_ = true;
  }
}

// A new trial: the row becomes its characters, the view a fresh one.
void HostedSessionView::show_trial(const SessionView& s,
                                   const std::function<void(const std::vector<std::size_t>&)>& show_row) {
  std::vector<std::size_t> row;
  shown_utf8_.clear();
  for (const char32_t c : s.trial.characters) {
    row.push_back(index_of_.at(c));
    shown_utf8_.push_back(characters_[row.back()].utf8);
  }
  // Stroke events count strokes within their character; a one-character trial (the usual) names its own.
  shown_typical_ids_ = typical_ids_of(characters_[row.front()].model);
  show_row(row);
  view_.emplace();
  view_->whole_row = true;
  view_->number = s.trial.index + 1;
  view_->guidance = s.guidance;
  view_->condition = s.trial.condition;
  channel_.reset();
  scene_ = trial_scene(s.trial);
  if (const std::optional<QuizOptions>& quiz =
          link_.manifest->protocol.protocol.condition(s.trial.condition).quiz)
    view_->quiz.emplace(scene_, *quiz);
}

Scene HostedSessionView::trial_scene(const PlannedTrial& trial) const {
  std::vector<Character> models;
  for (const char32_t c : trial.characters) models.push_back(characters_[index_of_.at(c)].model);
  return Scene::lay_out(models);
}

void HostedSessionView::start_trial() { link_.host->start_trial(); }

void HostedSessionView::request_stop() { link_.host->request_stop(); }

bool HostedSessionView::finished() const { return link_.done->load(); }

void HostedSessionView::fill_panel(PanelInput& panel) const {
  const SessionView& s = state_;
  const SessionSetup& setup = link_.manifest->setup;
  std::string characters;
  // The panel names the outline's colour only when every character of the trial is drawn with one.
  bool outlined = true;
  for (const char32_t c : s.trial.characters) {
    const TrainerCharacter& character = characters_[index_of_.at(c)];
    characters += character.utf8;
    outlined = outlined && character.outlined();
  }
  panel.character = characters;
  panel.outlined = outlined;
  char line[256];
  std::snprintf(line, sizeof line, "Session %s, subject %s\ntrial %zu of %zu (%s), condition %s: %s",
                link_.manifest->protocol.protocol.name.c_str(), setup.subject.id.c_str(), s.trial.index + 1,
                s.total, to_string(s.trial.phase), s.trial.condition.c_str(), mode_meaning(s.mode));
  panel.session = s.phase == SessionPhase::waiting ? "Session " + link_.manifest->session_id : line;
  switch (s.phase) {
    case SessionPhase::waiting:
      panel.prompt = "starting...";
      break;
    case SessionPhase::announced:
      panel.prompt = "Next: write " + characters + (unattended_ ? "" : "\npress Space to start");
      break;
    case SessionPhase::resting: {
      const double left =
          std::chrono::duration<double>(s.rest_until - std::chrono::steady_clock::now()).count();
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
      panel.prompt = "Session over" + std::string(unattended_ ? "" : "\nEsc closes the window");
      break;
  }
  panel.characters = s.trial.characters.size();
}

}  // namespace calligraphy::trainer
