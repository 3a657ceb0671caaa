#pragma once
// The quiz judged live in the window (analysis/quiz.hpp: the stroke matcher, as the renderer judges): the
// pen's positions arrive on the window thread through the display channel's trace queue, one `QuizSession`
// per character of the trial's scene judges each stroke the moment the pen lifts, and the window shows the
// verdicts at once. Never on the servo thread: a judgement takes up to milliseconds.
//
// The samples are the ones the saved record judges after the trial (quiz_characters): the
// same time and HIP per tick, pen down within `calligraphy score`'s contact threshold above the paper
// (PenTraceCsvOptions), each routed to its character by the stroke active at that tick. The verdicts agree
// with the saved ones as long as no trace point was dropped (`dropped_points`).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/display.hpp"

namespace calligraphy::trainer {

/// A judged stroke's written trace, kept for drawing (a miss flashes in red for a while).
struct QuizInk {
  std::size_t character = 0;
  std::vector<Vec2> points_m;  ///< in the trial's metres, thinned for drawing
  QuizEvent::Kind verdict = QuizEvent::Kind::stroke_missed;
  std::chrono::steady_clock::time_point judged_at;
};

class LiveQuiz {
 public:
  /// One quiz per character of `scene`. Throws InvalidArgument for bad options.
  LiveQuiz(const Scene& scene, const QuizOptions& options);

  /// One trace point (in tick order). Returns the events it caused, each with its character.
  std::vector<std::pair<std::size_t, QuizEvent>> feed(const TracePoint& point);
  /// The trial ended: judges pen-down runs still open. Returns their events.
  std::vector<std::pair<std::size_t, QuizEvent>> finish();
  /// Counts trace points the window never received (a full queue): the live verdicts may then differ.
  void note_dropped(std::uint64_t dropped) noexcept { dropped_points_ = dropped; }

  [[nodiscard]] const std::vector<QuizSession>& sessions() const noexcept { return sessions_; }
  /// Every character's events so far, as `quiz_characters` returns them.
  [[nodiscard]] std::vector<std::vector<QuizEvent>> events() const;
  /// The pen-down run being written (for drawing), and the character it is routed to.
  [[nodiscard]] const std::vector<Vec2>& open_run() const noexcept { return open_run_; }
  [[nodiscard]] const std::vector<QuizInk>& inks() const noexcept { return inks_; }
  /// A stroke the quiz credited assisted (stroke_assisted): shown drawn once from `at` in the
  /// demonstration's ink, as a trial's assisted stroke is (TrialView::assisted), then kept filled so.
  struct Assisted {
    std::size_t character = 0;
    std::size_t stroke = 0;  ///< within that character
    std::chrono::steady_clock::time_point at;
  };
  /// The last stroke credited assisted, of any character; empty before the first.
  [[nodiscard]] const std::optional<Assisted>& last_assisted() const noexcept { return last_assisted_; }
  /// Whether `stroke` of `character` was credited assisted (not written).
  [[nodiscard]] bool assisted(std::size_t character, std::size_t stroke) const noexcept;
  /// The stroke to highlight per character (after a hint event, until that stroke is accepted or assisted).
  [[nodiscard]] const std::vector<std::optional<std::size_t>>& hinted() const noexcept { return hinted_; }
  /// The last judged stroke was written from its end to its start, per character.
  [[nodiscard]] const std::vector<bool>& last_backwards() const noexcept { return last_backwards_; }
  /// Why the last judged stroke was missed (none when it was accepted or too short), per character.
  [[nodiscard]] const std::vector<StrokeRefusal>& last_refusal() const noexcept { return last_refusal_; }
  /// The most recent event of any character, for the panel.
  [[nodiscard]] const std::optional<std::pair<std::size_t, QuizEvent>>& last_event() const noexcept {
    return last_event_;
  }
  [[nodiscard]] bool finished() const noexcept { return finished_; }
  /// Every stroke of every character accepted or assisted: the quiz, and so its trial, is complete.
  [[nodiscard]] bool complete() const noexcept;
  [[nodiscard]] std::uint64_t dropped_points() const noexcept { return dropped_points_; }

 private:
  [[nodiscard]] std::size_t character_of(std::uint32_t stroke_index) const;
  void take(std::size_t character, const std::vector<QuizEvent>& events,
            std::vector<std::pair<std::size_t, QuizEvent>>& out);

  double paper_z_m_ = 0.0;
  std::vector<QuizSession> sessions_;
  std::vector<std::size_t> first_stroke_;  // per character, over the scene
  std::vector<Vec2> open_run_;
  std::size_t open_character_ = 0;
  std::vector<QuizInk> inks_;
  std::vector<std::optional<std::size_t>> hinted_;
  std::vector<std::vector<bool>> assisted_;  // per character, per stroke
  std::optional<Assisted> last_assisted_;
  std::vector<bool> last_backwards_;
  std::vector<StrokeRefusal> last_refusal_;
  std::optional<std::pair<std::size_t, QuizEvent>> last_event_;
  bool finished_ = false;
  std::uint64_t dropped_points_ = 0;
};

/// "stroke 2: stroke_missed (misses 1 on the stroke, 1 in all, backwards)", "stroke 2: stroke_missed (misses
/// 2 on the stroke, 2 in all, wrong_order, wrote stroke 3)": one line for logs; strokes 1-based.
[[nodiscard]] std::string describe(const QuizEvent& event);

/// "0 misses", "1 miss", "2 misses": a count and the noun that agrees with it.
[[nodiscard]] std::string count_of(std::size_t count, std::string_view one, std::string_view many);

}  // namespace calligraphy::trainer
