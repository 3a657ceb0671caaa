#pragma once
/// \file active_stroke.hpp
/// The active character, active stroke and the feature-point stack of the active stroke (paper
/// sections 2.2 step 4, 4.3 and 6). Strokes are written in order; a written stroke is never active
/// again, so it cannot be written twice, and every character but the active one is masked. The active
/// element and the stroke's completion follow the pen's progress along the stroke
/// (stroke_progress.hpp), not the feature planes alone. Servo path: no allocation, noexcept.
#include <cstddef>
#include <cstdint>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"

namespace calligraphy {

/// What `ActiveStroke::advance` or `lift` did this tick.
struct StrokeProgress {
  int elements_passed = 0;                      ///< corners (feature points) the pen went round this tick
  bool stroke_completed = false;                ///< the stroke is written; the next stroke is now active
  StrokeRefusal refusal = StrokeRefusal::none;  ///< `lift` of a stroke not written: why
  /// `lift` of a stroke refused for the `assist_after_misses`-th time: it is credited as assisted (not
  /// written) and the next stroke is now active.
  bool stroke_assisted = false;
};

class ActiveStroke {
 public:
  /// Starts at the first stroke of the first character. `scene` must outlive this object;
  /// `acceptance` must be valid (StrokeAcceptance::validate).
  explicit ActiveStroke(const Scene& scene, const StrokeAcceptance& acceptance = {}) noexcept;

  /// Back to the first stroke, nothing written.
  void reset() noexcept;
  /// The pen entered WS at `tip_m` [m]: an attempt at the active stroke begins.
  void begin(const Vec2& tip_m) noexcept;
  /// The pen at `tip_m` [m] in WS: pops the feature points it has gone round (the elements whose arc
  /// its progress passed, possibly several in one tick); completes the stroke when a pen that passed the
  /// end leaves the end neighbourhood back along the stroke (most strokes complete at `lift`). Does
  /// nothing outside an attempt.
  StrokeProgress advance(const Vec2& tip_m) noexcept;
  /// Pen lifted in WS: the stroke is written when the attempt meets the tolerances (short of the end or
  /// past it); otherwise its feature points are loaded again (section 4.3.3), `refusal` says why and, when
  /// `counts_as_miss` (StrokeAcceptance::counts_as_miss of the pen-down), the refusal counts as a miss; at
  /// `assist_after_misses` misses the stroke is credited as assisted and the next stroke is active.
  StrokeProgress lift(bool counts_as_miss = true) noexcept;
  /// A pen-down that never came near the active stroke's start (never WS) was lifted, and counts as a miss
  /// (StrokeAcceptance::counts_as_miss): `refusal` wrong_place; the hint and the assisted credit follow
  /// the misses as after `lift`. Does nothing once finished.
  StrokeProgress miss() noexcept;

  [[nodiscard]] bool finished() const noexcept { return character_ >= scene_->characters.size(); }
  /// Indices of the active character, its stroke, and the active element; meaningless once finished.
  [[nodiscard]] std::size_t character_index() const noexcept { return character_; }
  [[nodiscard]] std::size_t stroke_index() const noexcept { return stroke_; }
  [[nodiscard]] std::size_t element_index() const noexcept { return element_; }
  /// Strokes written so far, over all characters (not those credited as assisted).
  [[nodiscard]] std::size_t strokes_written() const noexcept { return written_; }
  /// Strokes credited as assisted so far, over all characters.
  [[nodiscard]] std::size_t strokes_assisted() const noexcept { return assisted_; }
  /// Refused attempts at the active stroke.
  [[nodiscard]] std::uint32_t misses() const noexcept { return misses_; }
  /// The active stroke is to be shown as a hint: misses >= `hint_after_misses` (> 0).
  [[nodiscard]] bool hint_shown() const noexcept;

  [[nodiscard]] const PlacedCharacter* character() const noexcept;
  [[nodiscard]] const PlacedStroke* stroke() const noexcept;
  [[nodiscard]] const StrokeElement* element() const noexcept;
  /// Attraction factor at parameter t of the active element, interpolated between its feature points.
  [[nodiscard]] double attraction(double t) const noexcept;
  /// The running (or last) attempt at the active stroke.
  [[nodiscard]] const StrokeProgressTracker& attempt() const noexcept { return attempt_; }
  [[nodiscard]] const StrokeAcceptance& acceptance() const noexcept { return acceptance_; }

 private:
  void next_stroke() noexcept;                         // the active stroke is done (written or assisted)
  void count_miss(StrokeProgress& progress) noexcept;  // a refused pen-down: maybe credited assisted

  const Scene* scene_;
  StrokeAcceptance acceptance_;
  StrokeProgressTracker attempt_;
  bool attempt_open_ = false;  // begun and neither written nor lifted
  std::size_t character_ = 0;
  std::size_t stroke_ = 0;
  std::size_t element_ = 0;  // top of the feature-point stack: the element being written
  std::size_t written_ = 0;
  std::size_t assisted_ = 0;
  std::uint32_t misses_ = 0;  // refused attempts at the active stroke
};

}  // namespace calligraphy
