#pragma once
/// \file timing_target.hpp
/// The moving target of the `timing` guidance mode: on each stroke of the scene a point that travels the
/// stroke's elements from its start to its end in T_k = L_k / v (L_k the stroke's arc length, v the mean
/// speed) with the minimum-jerk profile s(u) = L_k (10 u^3 - 15 u^4 + 6 u^5), u = t / T_k, of Flash & Hogan
/// (1985, J Neurosci 5:1688), the smoothest point-to-point motion and a fair model of a fluent stroke. The
/// stroke's clock starts when the pen enters WS on it (as in replay). Kept on the trainee's active element
/// as a replay's point is (teacher_replay.hpp): the element's end when the target is further on, its start
/// when behind.
#include <cstddef>
#include <vector>

#include "calligraphy/model/scene.hpp"

namespace calligraphy {

class TimingTarget {
 public:
  /// No scene: `empty()`.
  TimingTarget() = default;
  /// Tabulates arc length along every stroke of `scene`. Throws InvalidArgument for a speed that is not
  /// finite and > 0.
  TimingTarget(const Scene& scene, double mean_speed_m_s);

  [[nodiscard]] bool empty() const noexcept { return strokes_.empty(); }
  /// Duration [s] of stroke `scene_stroke` (0-based over the scene); 0 for an index out of range.
  [[nodiscard]] double duration_s(std::size_t scene_stroke) const noexcept;
  /// Where the target is `elapsed_s` [s] into stroke `scene_stroke`: its element's index and the parameter
  /// on it; clamped to the stroke's start and end. Servo path: noexcept, no allocation.
  struct Place {
    std::size_t element = 0;
    double parameter = 0.0;
  };
  [[nodiscard]] Place place(std::size_t scene_stroke, double elapsed_s) const noexcept;
  /// The target on the trainee's active element `element` (index `element_index` in the stroke) [m].
  [[nodiscard]] Vec2 attraction_point(std::size_t scene_stroke, double elapsed_s, std::size_t element_index,
                                      const StrokeElement& element) const noexcept;

 private:
  // Arc length at evenly spaced parameters of each element, cumulative over the stroke.
  struct StrokeTable {
    std::vector<double> arc_m;  // (samples + 1) per element, cumulative from the stroke's start
    std::size_t elements = 0;
    double duration_s = 0.0;
  };
  std::vector<StrokeTable> strokes_;
};

}  // namespace calligraphy
