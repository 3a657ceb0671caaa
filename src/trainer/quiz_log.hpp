#pragma once
// The trainer's log of a trial's quiz and refused strokes: each live verdict and each refused stroke on
// stderr (the test harness and logs read them), a screenshot asked for on the first frame that shows a
// judged stroke, and, once a trial's trace is whole, the live verdicts checked against the saved record's.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "trainer/live_quiz.hpp"
#include "trainer/trial_view.hpp"

namespace calligraphy::trainer {

class QuizLog {
 public:
  /// `program` starts each line ("calligraphy train", "calligraphy session"); `screenshot_folder`, when
  /// not empty, is where a PNG is asked for after each judged stroke.
  QuizLog(std::string program, std::string screenshot_folder);

  /// The quiz's verdicts in `view` not logged yet: one line each, and a screenshot asked for after a judged
  /// stroke. `characters_utf8`: the trial's characters, in its scene's order.
  void log_verdicts(TrialView& view, std::span<const std::string> characters_utf8);
  /// A refused attempt not logged yet, once, as the panel words it.
  void log_refusal(TrialView& view, std::span<const std::string> characters_utf8);

  /// A screenshot is asked for: the next frame drawn is to be written as a PNG.
  [[nodiscard]] bool screenshot_requested() const noexcept { return !screenshot_.empty(); }
  /// The PNG the next frame is to be written to, or empty; the request is then cleared.
  [[nodiscard]] std::string take_screenshot_request();

 private:
  std::string program_;
  std::string screenshot_folder_;
  std::size_t verdicts_ = 0;  // judged strokes asked a screenshot for, to number them
  std::string screenshot_;
};

/// The saved record judges the whole trace after the trial (quiz_characters, with `options`, on `scene`):
/// prints whether the verdicts `quiz` gave live are the same ones, in words true for none, one and many;
/// `saved_record` says whether the trial is saved (`--session`) or only judged again for this line.
void check_quiz_against_trace(const LiveQuiz& quiz, const Scene& scene, const std::vector<TrialSample>& trace,
                              const QuizOptions& options, bool saved_record);

}  // namespace calligraphy::trainer
