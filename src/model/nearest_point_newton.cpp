// The multi-start Newton method (as msdfgen, Chlumsky's signed distance field generator, does for curves).
#include <algorithm>

#include "model/nearest_point_methods.hpp"

namespace calligraphy::detail {

double newton_step(const LocalCurve& curve, double t) noexcept {
  const CurveJet jet = local_jet(curve, t);
  const Vec2 offset = jet.point - curve.p;
  const double f = offset.dot(jet.first);
  const double slope = jet.first.squaredNorm() + offset.dot(jet.second);
  if (!(slope > 0.0)) return t;
  return std::clamp(t - f / slope, 0.0, 1.0);
}

NearestPoint nearest_point_newton(const LocalCurve& curve, int starts, int iterations) noexcept {
  if (curve.degree == 1) return local_segment_nearest(curve);
  NearestCandidate best(curve, 0.0);
  for (int start = 0; start < starts; ++start) {
    double t = (start + 0.5) / starts;
    for (int iteration = 0; iteration < iterations; ++iteration) {
      const double next = newton_step(curve, t);
      if (next == t) break;
      t = next;
    }
    best.offer(curve, t);
  }
  best.offer(curve, 1.0);
  return local_result(curve, best.t);
}

}  // namespace calligraphy::detail
