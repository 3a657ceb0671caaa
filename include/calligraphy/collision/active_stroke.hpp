#pragma once
/// \file active_stroke.hpp
/// The active character, active stroke and the feature-point stack of the active stroke (paper
/// sections 2.2 step 4, 4.3 and 6). Strokes are written in order; a written stroke is never active
/// again, so it cannot be written twice, and every character but the active one is masked.
/// Servo path: no allocation, noexcept.
#include <cstddef>

#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// What `ActiveStroke::advance` did this tick.
struct StrokeProgress {
  int planes_passed = 0;          ///< feature planes popped this tick
  bool stroke_completed = false;  ///< the last plane of the stroke popped; the next stroke is now active
};

class ActiveStroke {
 public:
  /// Starts at the first stroke of the first character. `scene` must outlive this object.
  explicit ActiveStroke(const Scene& scene) noexcept;

  /// Back to the first stroke, nothing written.
  void reset() noexcept;
  /// Pops every feature plane the tip has crossed (eq. 6), possibly several in one tick, and
  /// completes the stroke when its last plane pops. Tip on the paper plane [m]; `plane_margin_m` is
  /// the feature-plane hysteresis of `feature_plane_passed` [m].
  StrokeProgress advance(const Vec2& tip_m, double plane_margin_m = 0.0) noexcept;
  /// Pen lifted in WS: the active stroke's feature points are loaded again (section 4.3.3).
  void reload() noexcept;

  [[nodiscard]] bool finished() const noexcept { return character_ >= scene_->characters.size(); }
  /// Indices of the active character, its stroke, and the active element; meaningless once finished.
  [[nodiscard]] std::size_t character_index() const noexcept { return character_; }
  [[nodiscard]] std::size_t stroke_index() const noexcept { return stroke_; }
  [[nodiscard]] std::size_t element_index() const noexcept { return element_; }
  /// Strokes written so far, over all characters.
  [[nodiscard]] std::size_t strokes_written() const noexcept { return written_; }

  [[nodiscard]] const PlacedCharacter* character() const noexcept;
  [[nodiscard]] const PlacedStroke* stroke() const noexcept;
  [[nodiscard]] const StrokeElement* element() const noexcept;
  /// Attraction factor at parameter t of the active element, interpolated between its feature points.
  [[nodiscard]] double attraction(double t) const noexcept;

 private:
  void next_stroke() noexcept;

  const Scene* scene_;
  std::size_t character_ = 0;
  std::size_t stroke_ = 0;
  std::size_t element_ = 0;  // top of the feature-point stack: the element being written
  std::size_t written_ = 0;
};

}  // namespace calligraphy
