#pragma once
/// \file quiz.hpp
/// A stroke-order quiz for vision-only input, after Hanzi Writer's quiz (chanind/hanzi-writer,
/// src/Quiz.ts): pen samples go in; each time the pen lifts, the stroke just written is judged against the
/// stroke expected next, and accepted or missed. A run too short to judge (the rule by which `score_trace`
/// ignores a segment: analysis/score.hpp) is neither. Every other run is judged by the stroke matcher,
/// `match_stroke(character, expected, run, start_radius_m, acceptance)` (analysis/stroke_matcher.hpp):
/// the renderer's rule, so that the quiz, the renderer and `score_trace`'s segment verdicts agree on the
/// same trace (docs/stroke-acceptance.md). A run refused as backwards is a miss reported as backwards, or
/// accepted (still reported as backwards) with `accept_backwards`. After `hint_after_misses` misses on
/// one stroke, and after each further miss, a hint event asks to show the expected stroke. Not for the
/// servo thread: judging takes up to milliseconds per pen lift.
#include <cstddef>
#include <optional>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

/// Something the quiz tells its display.
struct QuizEvent {
  enum class Kind {
    stroke_accepted,      ///< the written stroke is the expected one: show it, expect the next
    stroke_missed,        ///< not the expected stroke: `refusal` says why
    hint,                 ///< show the expected stroke (after enough misses)
    character_completed,  ///< every stroke accepted
    too_short,            ///< a touch or a dot too short to judge: neither accepted nor a miss
  };
  Kind kind = Kind::stroke_missed;
  std::size_t stroke = 0;    ///< the expected stroke, 0-based in the character's stroke order
  bool backwards = false;    ///< the written stroke writes the expected one from its end to its start
  int misses_on_stroke = 0;  ///< misses on `stroke` so far (0 after it is accepted)
  int total_misses = 0;      ///< misses on the whole character so far
  double time_s = 0.0;       ///< time of the last pen-down sample of the judged stroke [s]
  std::size_t samples = 0;   ///< pen-down samples of the judged stroke
  /// Why the stroke matcher refused the written stroke (stroke_missed); none otherwise, also for a
  /// backwards stroke accepted with `accept_backwards`.
  StrokeRefusal refusal = StrokeRefusal::none;
  /// For a stroke_missed refused as wrong_order or wrong_stroke because the run wrote another stroke of the
  /// character: that stroke (StrokeMatch::matched_stroke), 0-based.
  std::optional<std::size_t> written_stroke;
};

/// "stroke_accepted", "stroke_missed", "hint", "character_completed", "too_short".
[[nodiscard]] const char* to_string(QuizEvent::Kind kind) noexcept;

/// One character's quiz.
class QuizSession {
 public:
  /// Throws InvalidArgument for bad options or a character without strokes or with a stroke without
  /// elements.
  explicit QuizSession(PlacedCharacter character, const QuizOptions& options = {});

  /// Adds one pen sample (time, position on the paper [m], pen down). When the pen lifts after a pen-down
  /// run, that run is judged; the events it caused are returned (usually none). Samples after the
  /// character is completed are ignored. Throws InvalidArgument naming the sample (counted from 0) when
  /// its time or position is not finite or its time is below the previous sample's.
  std::vector<QuizEvent> feed(const PenSample& sample);
  /// Judges a pen-down run still open (the input ended with the pen down); returns its events.
  std::vector<QuizEvent> finish();

  [[nodiscard]] std::size_t current_stroke() const noexcept { return current_; }
  [[nodiscard]] bool complete() const noexcept { return current_ >= character_.strokes.size(); }
  [[nodiscard]] int misses_on_stroke() const noexcept { return misses_on_stroke_; }
  [[nodiscard]] int total_misses() const noexcept { return total_misses_; }
  /// Every event so far, in order.
  [[nodiscard]] const std::vector<QuizEvent>& events() const noexcept { return events_; }
  [[nodiscard]] const PlacedCharacter& character() const noexcept { return character_; }

 private:
  std::vector<QuizEvent> judge_segment();

  PlacedCharacter character_;
  QuizOptions options_;
  std::vector<PenSample> segment_;  // the pen-down run being written
  std::size_t current_ = 0;
  int misses_on_stroke_ = 0;
  int total_misses_ = 0;
  std::size_t samples_fed_ = 0;
  double last_time_s_ = 0.0;
  std::vector<QuizEvent> events_;
};

/// The quiz events of each character of a trial's trace [`scene.characters.size()` lists]: the trace's
/// samples of each character (a tick belongs to the character whose strokes hold the active stroke; after
/// the last stroke, to the last character), pen down within PenTraceCsvOptions' contact threshold of the
/// paper, fed through a `QuizSession` per character. The verdicts a saved quiz trial's record holds; a
/// window judging live must show the same ones.
[[nodiscard]] std::vector<std::vector<QuizEvent>> quiz_characters(const Scene& scene,
                                                                  const std::vector<TrialSample>& trace,
                                                                  const QuizOptions& options);

}  // namespace calligraphy
