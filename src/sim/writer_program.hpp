#pragma once
// The simulated writer's motion program (private to the sim module): segments of minimum-jerk motion
// (Flash & Hogan 1985) along polylines, advanced by a phase whose rate the writer sets online, so that
// a segment keeps its bell-shaped speed profile while its duration follows the writer's pace.
#include <cstddef>
#include <limits>
#include <vector>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::writer_detail {

// The segments' shortest durations and the hover (docs/writer.md, "Movement"): assumed figures of an
// unhurried writer.
constexpr double kTravelMinimum_s = 0.3;  // shortest pen-up move between strokes
constexpr double kDescend_s = 0.2;        // quick descent to just above the start
constexpr double kTouchDown_s = 0.3;      // gentle touch-down onto the paper
constexpr double kLift_s = 0.2;           // lift at the end of a stroke
constexpr double kMinimumLeg_s = 0.15;    // shortest leg of a stroke (between corners)
constexpr double kHoverHeight_m = 0.002;  // descent ends this far above the paper

enum class SegmentKind {
  travel,   // pen up, towards the next start
  descend,  // pen up to hovering above the start
  touch,    // onto the paper
  write,    // along a leg of a stroke (steered: speed from the seen error)
  lift,     // off the paper
  pause,    // holding still (a hesitation, the top of a mid-stroke lift)
  stray,    // sliding on the paper outside the character's box
};

/// Where the hand means to be and how fast it means to move there.
struct Motion {
  Vec3 position_m = Vec3::Zero();
  Vec3 velocity_m_s = Vec3::Zero();
};

struct Segment {
  SegmentKind kind = SegmentKind::travel;
  std::vector<Vec3> path;     // at least one point, device frame [m]
  std::vector<double> arc;    // cumulative length along path [m]
  double duration_s = 0.0;    // at speed factor 1
  bool steered = false;       // write segments: the rate follows the writer's speed factor
  bool aim_at_start = false;  // the writer corrects towards the stroke's start while on it
  bool mid_stroke = false;    // part of a lift in the middle of a stroke
  double follow_from_m = std::numeric_limits<double>::infinity();  // arc beyond which it is follow-through

  [[nodiscard]] double length_m() const { return arc.empty() ? 0.0 : arc.back(); }
  /// Point at arc length `s` [m], clamped to the path.
  [[nodiscard]] Vec3 at_arc(double s) const;
  /// Unit in-plane direction of the path at arc length `s` (zero for a point).
  [[nodiscard]] Vec2 direction_at_arc(double s) const;
  /// Point at phase `phase` in [0, 1] of the minimum-jerk profile.
  [[nodiscard]] Vec3 at_phase(double phase) const { return motion_at_phase(phase, 0.0).position_m; }
  /// Point [m] and velocity [m/s] at phase `phase` in [0, 1] while the phase advances at `rate_per_s`
  /// [1/s]: at_phase(phase), and its time derivative rate L mj'(phase) along the path's unit tangent.
  [[nodiscard]] Motion motion_at_phase(double phase, double rate_per_s) const;
  /// Minimum-jerk position profile on [0, 1]: 10 p^3 - 15 p^4 + 6 p^5 (Flash & Hogan 1985).
  [[nodiscard]] static double minimum_jerk(double phase);
  /// Its derivative d/dp: 30 p^2 (1 - p)^2, zero outside [0, 1].
  [[nodiscard]] static double minimum_jerk_slope(double phase);
};

/// The point `p` of the writing plane at height `z` [m].
inline Vec3 on_plane(const Vec2& p, double z) { return Vec3(p.x(), p.y(), z); }

/// A segment through `path` lasting max(minimum_s, length / speed_m_s) at speed factor 1.
Segment make_segment(SegmentKind kind, std::vector<Vec3> path, double speed_m_s, double minimum_s);

/// A steered write segment through `path` at `speed_m_s` (at least kMinimumLeg_s), follow-through beyond
/// `follow_from_m` of its arc [m].
Segment make_write_segment(std::vector<Vec3> path, double speed_m_s,
                           double follow_from_m = std::numeric_limits<double>::infinity());

/// Nearest point to `p` on the polyline `points` (at least one point) and the unit direction of the
/// polyline there (zero for a single point).
struct PolylineFoot {
  Vec2 foot = Vec2::Zero();
  Vec2 direction = Vec2::Zero();
};
PolylineFoot nearest_on_polyline(const std::vector<Vec2>& points, const Vec2& p);

}  // namespace calligraphy::writer_detail
