// The trainer's quiz log (quiz_log.hpp).
#include "trainer/quiz_log.hpp"

#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/trial/quiz_trace.hpp"
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
      std::fprintf(stderr, "%s: quiz %s complete, %s\n", who, utf8.c_str(),
                   count_of(static_cast<std::size_t>(event.total_misses), "miss", "misses").c_str());
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
                              const QuizOptions& options, bool saved_record) {
  const std::vector<std::vector<QuizEvent>> again = quiz_characters(scene, trace, options);
  const std::vector<std::vector<QuizEvent>> live = quiz.events();
  bool same = again.size() == live.size();
  std::size_t count = 0;  // the verdicts
  for (std::size_t c = 0; same && c < again.size(); ++c) {
    same = again[c].size() == live[c].size();
    for (std::size_t k = 0; same && k < again[c].size(); ++k) {
      const QuizEvent& a = again[c][k];
      const QuizEvent& b = live[c][k];
      same = a.kind == b.kind && a.stroke == b.stroke && a.backwards == b.backwards &&
             a.misses_on_stroke == b.misses_on_stroke && a.total_misses == b.total_misses &&
             a.time_s == b.time_s && a.samples == b.samples && a.refusal == b.refusal &&
             a.written_stroke == b.written_stroke;
      // Verdicts are the judged strokes; a hint and a completion are events beside them (compared too).
      if (a.kind == QuizEvent::Kind::stroke_accepted || a.kind == QuizEvent::Kind::stroke_missed ||
          a.kind == QuizEvent::Kind::too_short)
        ++count;
    }
  }
  // What the whole trace, judged again, is: the saved record's verdicts with --session, else nothing kept.
  const char* judged_again = saved_record ? "the saved record" : "the whole trace judged after the trial";
  if (same && count == 0) {
    std::fprintf(stderr, "calligraphy train: quiz: no stroke was judged, live or in %s\n", judged_again);
  } else if (same) {
    std::fprintf(stderr, "calligraphy train: quiz: %s, the same as in %s\n",
                 count_of(count, "live verdict", "live verdicts").c_str(), judged_again);
  } else {
    std::fprintf(
        stderr,
        "calligraphy train: warning: quiz: the live verdicts differ from those of %s, which judges "
        "the whole trace (%s did not reach the window)\n",
        judged_again,
        count_of(static_cast<std::size_t>(quiz.dropped_points()), "trace point", "trace points").c_str());
  }
}

}  // namespace calligraphy::trainer
