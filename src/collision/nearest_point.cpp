// PROVISIONAL until the nearest-point module of issue 4 is merged: segment projection, and for Bezier
// elements dense sampling followed by Newton refinement. Replaced wholesale by that module.
#include "calligraphy/nearest_point.hpp"

#include <algorithm>
#include <cmath>

#include "calligraphy/errors.hpp"

namespace calligraphy {

NearestPoint nearest_point_on_segment(const Vec2& a, const Vec2& b, const Vec2& p) noexcept {
  const Vec2 edge = b - a;
  const double length_sq = edge.squaredNorm();
  double t = length_sq > 0.0 ? std::clamp((p - a).dot(edge) / length_sq, 0.0, 1.0) : 0.0;
  const Vec2 foot = a + t * edge;
  return {t, foot, (p - foot).norm()};
}

NearestPoint nearest_point(const StrokeElement& element, const Vec2& p, const NearestPointOptions& options) {
  if (!p.allFinite()) throw InvalidArgument("nearest_point: query point is not finite");
  if (!(options.tolerance > 0.0)) throw InvalidArgument("nearest_point: tolerance must be > 0");
  if (element.degree == 1) return nearest_point_on_segment(element.start(), element.end(), p);
  constexpr int kSamples = 64;
  NearestPoint best{0.0, element.start(), (p - element.start()).norm()};
  for (int i = 1; i <= kSamples; ++i) {
    const double t = static_cast<double>(i) / kSamples;
    const Vec2 q = element.point(t);
    const double d = (p - q).norm();
    if (d < best.distance) best = {t, q, d};
  }
  double t = best.t;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Vec2 d = element.point(t) - p;
    const Vec2 d1 = element.derivative(t);
    const double h = 1e-7;
    const Vec2 d2 = (element.derivative(std::min(1.0, t + h)) - element.derivative(std::max(0.0, t - h))) / (2 * h);
    const double denom = d1.squaredNorm() + d.dot(d2);
    if (!(denom > 0.0)) break;
    const double next = std::clamp(t - d.dot(d1) / denom, 0.0, 1.0);
    if (std::abs(next - t) < 1e-14) break;
    t = next;
  }
  const Vec2 q = element.point(t);
  const double d = (p - q).norm();
  if (d < best.distance) best = {t, q, d};
  return best;
}

}  // namespace calligraphy
