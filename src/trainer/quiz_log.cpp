// The trainer's quiz log (quiz_log.hpp).
#include "trainer/quiz_log.hpp"

#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/study/quiz.hpp"
#include "trainer/panel.hpp"

namespace calligraphy::trainer {

QuizLog::QuizLog(std::string program, std::string screenshot_folder)
    : program_(std::move(program)), screenshot_folder_(std::move(screenshot_folder)) {}

void QuizLog::log_verdicts(TrialView& view, std::span<const std::string> characters_utf8) {
  if (!view.quiz) return;
  const char* who = program_.c_str();
  for (const auto& [character, event] : view.quiz_unlogged) {
    const std::string& utf8 = characters_utf8[character];
    std::fprintf(stderr, "%s: quiz %s %s\n", who, utf8.c_str(), describe(event).c_str());
    if (event.kind == QuizEvent::Kind::character_completed) {
      std::fprintf(stderr, "%s: quiz %s complete, %d misses\n", who, utf8.c_str(), event.total_misses);
    }
    const bool judged = event.kind == QuizEvent::Kind::stroke_accepted ||
                        event.kind == QuizEvent::Kind::stroke_missed ||
                        event.kind == QuizEvent::Kind::too_short;
    if (judged && !screenshot_folder_.empty()) {
      char name[64];
      std::snprintf(name, sizeof name, "quiz-%02zu-%s.png", ++verdicts_, to_string(event.kind));
      screenshot_ = (std::filesystem::path(screenshot_folder_) / name).string();
    }
  }
  view.quiz_unlogged.clear();
}

void QuizLog::log_refusal(TrialView& view, std::span<const std::string> characters_utf8) {
  if (view.refusals == view.refusals_logged) return;
  view.refusals_logged = view.refusals;
  if (!view.refused) return;  // already replaced by a touch-down in the same frame
  const RefusedStroke& r = *view.refused;
  const RefusalWords words = learner_words(r.refusal);
  std::fprintf(stderr, "%s: %s stroke %u not written: %s: %s (%s; %s)\n", program_.c_str(),
               characters_utf8[r.character].c_str(), r.stroke + 1, words.what, words.advice,
               to_string(r.refusal), r.judged_from_path ? "judged from the pen-down path" : "judged in WS");
}

std::string QuizLog::take_screenshot_request() { return std::exchange(screenshot_, {}); }

void check_quiz_against_trace(const LiveQuiz& quiz, const Scene& scene, const std::vector<TrialSample>& trace,
                              const QuizOptions& options) {
  const std::vector<std::vector<QuizEvent>> saved = quiz_characters(scene, trace, options);
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
             a.time_s == b.time_s && a.samples == b.samples && a.refusal == b.refusal &&
             a.written_stroke == b.written_stroke;
      ++count;
    }
  }
  if (same) {
    std::fprintf(stderr, "calligraphy train: quiz: the %zu live verdicts are the saved record's\n", count);
  } else {
    std::fprintf(stderr,
                 "calligraphy train: warning: quiz: the live verdicts differ from the saved record's, which "
                 "judges the whole trace (%llu trace points did not reach the window)\n",
                 static_cast<unsigned long long>(quiz.dropped_points()));
  }
}

}  // namespace calligraphy::trainer
