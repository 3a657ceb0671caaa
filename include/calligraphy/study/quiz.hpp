#pragma once
/// \file quiz.hpp
/// A stroke-order quiz for vision-only input, after Hanzi Writer's quiz (chanind/hanzi-writer,
/// src/Quiz.ts and src/strokeMatches.ts): pen samples go in; each time the pen lifts, the stroke just
/// written is judged against the stroke expected next, and accepted or missed. The judgement is
/// `score_trace`'s (trial/score.hpp: Hanzi Writer's five tests with a leniency): the written stroke is
/// scored against the expected stroke alone. As in Hanzi Writer, when it passes but matches a later
/// stroke more closely (a smaller mean distance), it is tested again with the leniency scaled by
/// 0.6 (d_later + d_expected) / (2 d_expected), i.e. by 0.3 to 0.6. A stroke that matches only from its
/// end to its start is reported as backwards (and accepted only with `accept_backwards`). After
/// `hint_after_misses` misses on one stroke, and after each further miss, a hint event asks to show the
/// expected stroke. Not for the servo thread: judging takes up to milliseconds per pen lift.
#include <cstddef>
#include <optional>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/score.hpp"

namespace calligraphy {

/// Something the quiz tells its display.
struct QuizEvent {
  enum class Kind {
    stroke_accepted,      ///< the written stroke is the expected one: show it, expect the next
    stroke_missed,        ///< not the expected stroke (wrong place, shape, direction or order)
    hint,                 ///< show the expected stroke (after enough misses)
    character_completed,  ///< every stroke accepted
    too_short,            ///< a touch or a dot too short to judge: neither accepted nor a miss
  };
  Kind kind = Kind::stroke_missed;
  std::size_t stroke = 0;    ///< the expected stroke, 0-based in the character's stroke order
  bool backwards = false;    ///< the written stroke matched the expected one only from its end to its start
  int misses_on_stroke = 0;  ///< misses on `stroke` so far (0 after it is accepted)
  int total_misses = 0;      ///< misses on the whole character so far
  double time_s = 0.0;       ///< time of the last pen-down sample of the judged stroke [s]
  std::size_t samples = 0;   ///< pen-down samples of the judged stroke
  /// A later stroke the written one matched more closely (the leniency was then lowered), 0-based.
  std::optional<std::size_t> closer_later_stroke;
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
  struct Verdict {
    bool matched = false;  // forwards or backwards
    bool backwards = false;
    bool too_short = false;
    double mean_distance_m = 0.0;
  };
  Verdict judge(std::size_t stroke, double leniency) const;
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

}  // namespace calligraphy
