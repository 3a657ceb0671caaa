#pragma once
// The stroke-order demonstration's timing (pure, no window): each stroke drawn along the data's median at a
// person's pace, one after the other with a pause between them, as Hanzi Writer animates a character.
//
// Pace: a mean speed of 80 mm/s along the median, inside the 60-110 mm/s of the pointer traces that stroke
// acceptance is measured with (docs/stroke-acceptance.md), each stroke timed as a minimum-jerk motion (Flash
// & Hogan 1985: the arc length goes as 10 t^3 - 15 t^4 + 6 t^5 of the normalised time, slow at both ends,
// peak speed 1.875 times the mean), so the pen is seen to start, run and stop as a hand does. A dot is given
// at least kMinStrokeS to be seen. Between strokes the pen is lifted for `pause_s` (0.5 s: about a stroke's
// time, shorter than Hanzi Writer's default one second between strokes, delayBetweenStrokes).
#include <cstddef>
#include <vector>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy::trainer {

struct DemoPace {
  double speed_m_s = 0.08;  ///< mean speed along a stroke [m/s], > 0
  double pause_s = 0.5;     ///< pen-up time before each stroke [s], >= 0
};

/// The least time a stroke is drawn in [s].
inline constexpr double kMinStrokeS = 0.25;

/// Where a demonstration is at one moment.
struct DemoFrame {
  std::size_t stroke = 0;  ///< the stroke being drawn, index into the demonstration's strokes
  double fraction = 0.0;   ///< of its arc length drawn, in [0, 1] (0 during the pause before it)
  bool done = false;       ///< every stroke is drawn (stroke is then the count, fraction 1)
};

/// The timing of one demonstration of strokes of the given lengths [m], in order.
class DemoSchedule {
 public:
  DemoSchedule() = default;
  DemoSchedule(std::vector<double> stroke_lengths_m, DemoPace pace);
  /// The frame at `t_s` seconds from the demonstration's start (clamped at 0).
  [[nodiscard]] DemoFrame at(double t_s) const noexcept;
  /// From the start to the end of the last stroke [s].
  [[nodiscard]] double duration_s() const noexcept;
  [[nodiscard]] std::size_t strokes() const noexcept { return durations_s_.size(); }
  /// The drawing time of stroke `k` [s].
  [[nodiscard]] double stroke_duration_s(std::size_t k) const { return durations_s_.at(k); }

 private:
  std::vector<double> durations_s_;
  DemoPace pace_;
};

/// A demonstration as it is now, to draw: the strokes of `placed` (trial metres, the character laid out as
/// its trial lays it out) over the row's character `box`, in order, up to `frame`.
struct DemoView {
  std::size_t box = 0;
  const PlacedCharacter* placed = nullptr;
  DemoFrame frame;
  std::size_t strokes = 0;
};

/// The minimum-jerk share of the way covered at normalised time `tau` in [0, 1] (clamped).
[[nodiscard]] double minimum_jerk(double tau) noexcept;

/// Length of a polyline [its units].
[[nodiscard]] double polyline_length(const std::vector<Vec2>& points) noexcept;

/// The first `fraction` (in [0, 1]) of a polyline by arc length: its points up to there and the point there.
[[nodiscard]] std::vector<Vec2> polyline_head(const std::vector<Vec2>& points, double fraction);

}  // namespace calligraphy::trainer
