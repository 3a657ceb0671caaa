#include "sim/writer_program.hpp"

#include <algorithm>
#include <utility>

namespace calligraphy::writer_detail {

double Segment::minimum_jerk(double phase) {
  const double p = std::clamp(phase, 0.0, 1.0);
  return p * p * p * (10.0 - 15.0 * p + 6.0 * p * p);
}

double Segment::minimum_jerk_slope(double phase) {
  if (!(phase > 0.0 && phase < 1.0)) return 0.0;
  const double q = phase * (1.0 - phase);
  return 30.0 * q * q;
}

Motion Segment::motion_at_phase(double phase, double rate_per_s) const {
  const double s = length_m() * minimum_jerk(phase);
  const auto upper = std::upper_bound(arc.begin(), arc.end(), s);
  if (upper == arc.end()) return {path.back(), Vec3::Zero()};  // at the end, where the speed is zero
  if (upper == arc.begin()) return {path.front(), Vec3::Zero()};
  const auto i = static_cast<std::size_t>(upper - arc.begin());
  const double span = arc[i] - arc[i - 1];
  if (!(span > 0.0)) return {path[i - 1], Vec3::Zero()};
  const Vec3 leg = path[i] - path[i - 1];
  // d/dt of the point at arc L mj(phase): the phase's rate times L mj'(phase), along the leg.
  const double speed_m_s = rate_per_s * length_m() * minimum_jerk_slope(phase);
  return {path[i - 1] + ((s - arc[i - 1]) / span) * leg, (speed_m_s / span) * leg};
}

Vec3 Segment::at_arc(double s) const {
  const auto upper = std::upper_bound(arc.begin(), arc.end(), s);
  if (upper == arc.end()) return path.back();
  if (upper == arc.begin()) return path.front();
  const auto i = static_cast<std::size_t>(upper - arc.begin());
  const double span = arc[i] - arc[i - 1];
  const double f = span > 0.0 ? (s - arc[i - 1]) / span : 0.0;
  return path[i - 1] + f * (path[i] - path[i - 1]);
}

Vec2 Segment::direction_at_arc(double s) const {
  if (path.size() < 2) return Vec2::Zero();
  auto upper = std::upper_bound(arc.begin(), arc.end(), s);
  if (upper == arc.end()) --upper;
  if (upper == arc.begin()) ++upper;
  const auto i = static_cast<std::size_t>(upper - arc.begin());
  const Vec2 d = (path[i] - path[i - 1]).head<2>();
  const double n = d.norm();
  return n > 0.0 ? Vec2(d / n) : Vec2(Vec2::Zero());
}

Segment make_segment(SegmentKind kind, std::vector<Vec3> path, double speed_m_s, double minimum_s) {
  Segment s;
  s.kind = kind;
  s.arc.push_back(0.0);
  for (std::size_t i = 1; i < path.size(); ++i)
    s.arc.push_back(s.arc.back() + (path[i] - path[i - 1]).norm());
  s.path = std::move(path);
  s.duration_s = std::max(minimum_s, s.arc.back() / speed_m_s);
  return s;
}

Segment make_write_segment(std::vector<Vec3> path, double speed_m_s, double follow_from_m) {
  Segment s = make_segment(SegmentKind::write, std::move(path), speed_m_s, kMinimumLeg_s);
  s.steered = true;
  s.follow_from_m = follow_from_m;
  return s;
}

PolylineFoot nearest_on_polyline(const std::vector<Vec2>& points, const Vec2& p) {
  PolylineFoot best;
  best.foot = points.front();
  double best_distance = (p - points.front()).squaredNorm();
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Vec2 a = points[i - 1];
    const Vec2 d = points[i] - a;
    const double length2 = d.squaredNorm();
    if (length2 == 0.0) continue;
    const double u = std::clamp((p - a).dot(d) / length2, 0.0, 1.0);
    const Vec2 foot = a + u * d;
    const double distance = (p - foot).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best.foot = foot;
      best.direction = d / std::sqrt(length2);
    }
  }
  if (best.direction.isZero() && points.size() >= 2) {
    const Vec2 d = points[1] - points[0];
    if (d.norm() > 0.0) best.direction = d.normalized();
  }
  return best;
}

}  // namespace calligraphy::writer_detail
