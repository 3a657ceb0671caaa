// The trainer's quiz log: each live verdict on stderr (and a screenshot when asked), and the live verdicts
// checked against those the saved record gives for the whole trace; each refused stroke on stderr.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "calligraphy/study/quiz.hpp"
#include "trainer/panel.hpp"
#include "trainer/trainer_app.hpp"

namespace calligraphy::trainer {

// The quiz's new verdicts: one stderr line each (the test harness and logs read them), and a screenshot
// of the frame that first shows a judged stroke when asked.
void TrainerApp::log_quiz(TrialView& view) {
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

// A refused attempt, as the panel words it, once on stderr (the test harness and logs read it).
void TrainerApp::log_refusal(TrialView& view) {
  if (view.refusals == view.refusals_logged) return;
  view.refusals_logged = view.refusals;
  if (!view.refused) return;  // already replaced by a touch-down in the same frame
  const RefusedStroke& r = *view.refused;
  const RefusalWords words = learner_words(r.refusal);
  std::fprintf(stderr, "%s: %s stroke %u not written: %s: %s (%s; %s)\n",
               session_ ? "calligraphy session" : "calligraphy train",
               character_utf8(view, r.character).c_str(), r.stroke + 1, words.what, words.advice,
               to_string(r.refusal), r.judged_from_path ? "judged from the pen-down path" : "judged in WS");
}

std::string TrainerApp::character_utf8(const TrialView& view, std::size_t character) const {
  if (session_ == nullptr) return options_.characters[view.character].utf8;
  const char32_t c = session_view_.trial.characters.at(character);
  return options_.characters[index_of_.at(c)].utf8;
}

// The saved record judges the whole trace after the trial (quiz_characters): the verdicts
// shown live must be the same ones.
void TrainerApp::check_quiz_against_trace(const LiveQuiz& quiz, const TrialResult& result) {
  const std::vector<std::vector<QuizEvent>> saved =
      quiz_characters(worker_.scene(), result.trace, options_.quiz_options);
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
