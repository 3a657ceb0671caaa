#pragma once
/// \file quiz.hpp
/// A stroke-order quiz for vision-only input, after Hanzi Writer's quiz (chanind/hanzi-writer,
/// src/Quiz.ts): pen samples go in; each time the pen lifts, the stroke just written is judged against the
/// stroke expected next, and accepted or missed. A run too short to judge (the rule by which `score_trace`
/// ignores a segment: analysis/score.hpp) is neither. Every other run is judged by the stroke matcher,
/// `match_stroke(character, expected, run, start_radius_m, acceptance)` (analysis/stroke_matcher.hpp):
/// the renderer's rule, so that the quiz, the renderer and `score_trace`'s segment verdicts agree on the
/// same trace (docs/stroke-acceptance.md). After the acceptance's `assist_after_misses` misses on one stroke
/// (0: never), that stroke is credited assisted, as Hanzi Writer's `markStrokeCorrectAfterMisses` marks it
/// correct: shown, not written, and the next stroke is expected. The quiz counts its misses as Hanzi Writer
/// does: every mismatch lifted (not the run `finish` judges). The renderer and `score_trace` count the same
/// misses on pen-downs that touch the character's box (StrokeAcceptance::counts_as_miss), none outside it;
/// with the acceptance's `miss_min_path_m` 0 (records before version 8) they count only attempts begun
/// within the start radius of the stroke's start (WS), and the quiz hints and credits sooner where
/// pen-downs never come near it (a stroke 8 mm off). A run
/// refused as backwards is a miss reported as backwards, or accepted (still reported as backwards) with
/// `accept_backwards`. After `hint_after_misses` misses on one stroke, and after each further miss but the
/// one that credits it, a hint event asks to show the expected stroke. Not for the servo thread: judging
/// takes up to milliseconds per pen lift. On the model and the stroke matcher only: a trial's trace is
/// judged through `quiz_characters` (trial/quiz_trace.hpp).
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"

namespace calligraphy {

/// How a quiz judges strokes: each pen-down run with the stroke matcher (`match_stroke`,
/// analysis/stroke_matcher.hpp), the rule the renderer and `score_trace` use (docs/stroke-acceptance.md);
/// misses and hints as in Hanzi Writer's quiz (chanind/hanzi-writer src/Quiz.ts).
struct QuizOptions {
  /// The stroke matcher's tolerances (SI units). The trainer gives its trials' (ForceLawParameters::
  /// acceptance) and a study session gives the renderer the quiz condition's, so that quiz and renderer
  /// agree.
  StrokeAcceptance acceptance{};
  /// Radius of the start neighbourhood (WS) a run must enter the stroke in [m]: the scene's
  /// (SceneLayout::start_radius_m). Finite, > 0.
  double start_radius_m = SceneLayout{}.start_radius_m;
  /// Overrides the acceptance's `hint_after_misses` (StrokeAcceptance, its one definition: default and
  /// range) when given: a hint (the expected stroke shown) after this many misses on one stroke, and after
  /// each further miss; 0: never. Empty: the acceptance's.
  std::optional<int> hint_after_misses{};
  /// The misses on one stroke after which the quiz shows a hint: the override, or the acceptance's.
  [[nodiscard]] int hint_after() const noexcept {
    return hint_after_misses ? *hint_after_misses : static_cast<int>(acceptance.hint_after_misses);
  }
  /// The misses on one stroke after which the quiz credits it assisted (0: never): the acceptance's
  /// `assist_after_misses`, the renderer's and `score_trace`'s count, with no override of the quiz's own
  /// (a protocol sets it as `quiz.acceptance.assist_after_misses`).
  [[nodiscard]] int assist_after() const noexcept { return static_cast<int>(acceptance.assist_after_misses); }
  /// A stroke written from its end to its start is accepted (and still reported as backwards).
  bool accept_backwards = false;
  /// Throws InvalidArgument naming the field when a value is out of range.
  void validate() const;
};

/// Something the quiz tells its display.
struct QuizEvent {
  enum class Kind {
    stroke_accepted,      ///< the written stroke is the expected one: show it, expect the next
    stroke_missed,        ///< not the expected stroke: `refusal` says why
    hint,                 ///< show the expected stroke (after enough misses)
    character_completed,  ///< every stroke accepted or assisted
    too_short,            ///< a touch or a dot too short to judge: neither accepted nor a miss
    /// After the miss that made `assist_after_misses` misses on the expected stroke: that stroke is shown
    /// (demonstrated) and credited assisted, not written; the next is expected. Follows its stroke_missed.
    stroke_assisted,
  };
  Kind kind = Kind::stroke_missed;
  std::size_t stroke = 0;  ///< the expected stroke, 0-based in the character's stroke order
  bool backwards = false;  ///< the written stroke writes the expected one from its end to its start
  /// Misses on `stroke` so far (not the run `finish` judges): 0 after it is accepted; the misses that
  /// earned the credit with stroke_assisted (as Hanzi Writer's onCorrectStroke gives them).
  int misses_on_stroke = 0;
  int total_misses = 0;     ///< every miss on the whole character so far
  double time_s = 0.0;      ///< time of the last pen-down sample of the judged stroke [s]
  std::size_t samples = 0;  ///< pen-down samples of the judged stroke
  /// Why the stroke matcher refused the written stroke (stroke_missed); none otherwise, also for a
  /// backwards stroke accepted with `accept_backwards`.
  StrokeRefusal refusal = StrokeRefusal::none;
  /// For a stroke_missed refused as wrong_order or wrong_stroke because the run wrote another stroke of the
  /// character: that stroke (StrokeMatch::matched_stroke), 0-based.
  std::optional<std::size_t> written_stroke;
};

/// "stroke_accepted", "stroke_missed", "hint", "character_completed", "too_short", "stroke_assisted".
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
  /// Judges a pen-down run still open (the input ended with the pen down); returns its events. Not lifted,
  /// it can be accepted or missed, never counted towards a hint or the assisted credit.
  std::vector<QuizEvent> finish();

  [[nodiscard]] std::size_t current_stroke() const noexcept { return current_; }
  [[nodiscard]] bool complete() const noexcept { return current_ >= character_.strokes.size(); }
  [[nodiscard]] int misses_on_stroke() const noexcept { return misses_on_stroke_; }
  [[nodiscard]] int total_misses() const noexcept { return total_misses_; }
  /// Strokes credited assisted so far (stroke_assisted events).
  [[nodiscard]] std::size_t strokes_assisted() const noexcept { return strokes_assisted_; }
  /// Every event so far, in order.
  [[nodiscard]] const std::vector<QuizEvent>& events() const noexcept { return events_; }
  [[nodiscard]] const PlacedCharacter& character() const noexcept { return character_; }

 private:
  std::vector<QuizEvent> judge_segment(bool lifted);

  PlacedCharacter character_;
  QuizOptions options_;
  std::vector<PenSample> segment_;  // the pen-down run being written
  std::size_t current_ = 0;
  int misses_on_stroke_ = 0;
  int total_misses_ = 0;
  std::size_t strokes_assisted_ = 0;
  std::size_t samples_fed_ = 0;
  double last_time_s_ = 0.0;
  std::vector<QuizEvent> events_;
};

/// The quiz events of one character's pen samples (time, position on the paper [m], pen down), in order: each
/// sample fed through a `QuizSession` with `options`, then `finish`. Throws what the session throws (bad
/// options or character, a sample named by its index in `samples`).
[[nodiscard]] std::vector<QuizEvent> quiz_character(const PlacedCharacter& character,
                                                    std::span<const PenSample> samples,
                                                    const QuizOptions& options);

}  // namespace calligraphy
