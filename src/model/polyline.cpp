#include "calligraphy/model/polyline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

namespace calligraphy {

// atan2 gives -pi for a vector pointing left with a y of -0 or below the smallest double's reach: -180, which
// is 180 in the documented range.
double direction_deg(const Vec2& v) { return wrap_deg(std::atan2(v.y(), v.x()) * 180.0 / std::numbers::pi); }

double wrap_deg(double a) {
  a = std::fmod(a, 360.0);
  if (a > 180.0) a -= 360.0;
  if (a <= -180.0) a += 360.0;
  return a;
}

double turn_deg(const Vec2& a, const Vec2& b) { return wrap_deg(direction_deg(b) - direction_deg(a)); }

std::vector<Vec2> without_repeats(std::span<const Vec2> pts) {
  std::vector<Vec2> out;
  for (const Vec2& p : pts) {
    if (out.empty() || p != out.back()) out.push_back(p);
  }
  return out;
}

double polyline_length(std::span<const Vec2> pts) {
  double length = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) length += (pts[i] - pts[i - 1]).norm();
  return length;
}

std::vector<Vec2> resample(std::span<const Vec2> pts, double step) {
  std::vector<Vec2> out;
  if (pts.empty() || !(step > 0.0)) return out;
  out.push_back(pts.front());
  double carried = 0.0;  // distance walked since the last emitted point
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const Vec2 a = pts[i - 1];
    const Vec2 d = pts[i] - a;
    const double len = d.norm();
    double s = step - carried;
    while (s < len) {
      out.push_back(a + d * (s / len));
      if (!(s + step > s)) break;  // a step below the rounding of s would never reach len
      s += step;
    }
    carried = len - (s - step);
  }
  if ((out.back() - pts.back()).norm() > 1e-9 * step) out.push_back(pts.back());
  return out;
}

double max_chord_deviation(std::span<const Vec2> pts) {
  double worst = 0.0;
  for (const Vec2& p : pts) worst = std::max(worst, distance_to_segment(pts.front(), pts.back(), p));
  return worst;
}

std::size_t farthest_from_chord(std::span<const Vec2> pts) {
  std::size_t best = 1;
  double worst = -1.0;
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const double d = distance_to_segment(pts.front(), pts.back(), pts[i]);
    if (d > worst) {
      worst = d;
      best = i;
    }
  }
  return best;
}

std::vector<Vec2> sample_element(const StrokeElement& element, int segments) {
  std::vector<Vec2> out;
  out.reserve(static_cast<std::size_t>(segments) + 1);
  for (int i = 0; i <= segments; ++i) out.push_back(element.point(static_cast<double>(i) / segments));
  return out;
}

double distance_to_polyline(const Vec2& p, std::span<const Vec2> pts) {
  if (pts.size() == 1) return (p - pts[0]).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < pts.size(); ++i) {
    best = std::min(best, distance_to_segment(pts[i - 1], pts[i], p));
  }
  return best;
}

namespace {

// max_distance_to_polyline, giving up (nullopt) when it would take more than `max_evaluations` segment
// distances.
std::optional<double> bounded_max_distance(std::span<const Vec2> points, std::span<const Vec2> pts,
                                           double stop_above, std::size_t max_evaluations) {
  if (pts.empty()) return points.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  if (pts.size() == 1) {
    double worst = 0.0;
    for (const Vec2& p : points) worst = std::max(worst, (p - pts[0]).norm());
    return worst;
  }
  // Same value as the max of distance_to_polyline: a point's scan stops once some segment is no
  // farther than the worst so far (it cannot raise the max), and starts at the previous point's
  // nearest segment, where consecutive points usually find theirs.
  const std::size_t segments = pts.size() - 1;
  std::size_t evaluations = 0;
  double worst = 0.0;
  std::size_t start = 0;
  for (const Vec2& p : points) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_segment = start;
    for (std::size_t k = 0; k < segments; ++k) {
      if (++evaluations > max_evaluations) return std::nullopt;
      const std::size_t i = (start + k) % segments;
      const double d = distance_to_segment(pts[i], pts[i + 1], p);
      if (d < best) {
        best = d;
        best_segment = i;
      }
      if (best <= worst) break;
    }
    worst = std::max(worst, best);
    if (worst > stop_above) return worst;
    start = best_segment;
  }
  return worst;
}

}  // namespace

double max_distance_to_polyline(std::span<const Vec2> points, std::span<const Vec2> pts, double stop_above) {
  return *bounded_max_distance(points, pts, stop_above, std::numeric_limits<std::size_t>::max());
}

std::optional<double> max_distance_to_polyline_within(std::span<const Vec2> points, std::span<const Vec2> pts,
                                                      std::size_t max_evaluations) {
  return bounded_max_distance(points, pts, std::numeric_limits<double>::infinity(), max_evaluations);
}

}  // namespace calligraphy
