// The paper's greedy subdivision for a CSE (section 4.3.2), reproduced as written so that its
// failure rate can be measured: split the current segment at its middle; of the two children keep
// the one owning the smallest of the distances from P to its three points (start, middle, end);
// stop when the distances from P to the two children's middle points differ by less than e; the
// solution is the middle of the chord joining those two middle points.
#include <algorithm>
#include <cmath>

#include "model/nearest_point_methods.hpp"

namespace calligraphy::detail {

namespace {
// Not in the paper: a bound so the loop ends even for e below the rounding of the distances.
constexpr int kMaxSubdivisionDepth = 60;

double local_distance(const LocalCurve& curve, double t) noexcept {
  return std::sqrt(local_squared_distance(curve, t));
}
}  // namespace

NearestPoint nearest_point_subdivision(const LocalCurve& curve, double e) noexcept {
  if (curve.degree == 1) return local_segment_nearest(curve);  // the paper's LSE case, section 4.3.1
  const double e_local = e / curve.scale;
  double a = 0.0;
  double b = 1.0;
  double distance_a = local_distance(curve, a);
  double distance_b = local_distance(curve, b);
  for (int depth = 0;; ++depth) {
    const double middle = 0.5 * (a + b);
    const double left_middle = 0.5 * (a + middle);
    const double right_middle = 0.5 * (middle + b);
    const double distance_middle = local_distance(curve, middle);
    const double distance_left = local_distance(curve, left_middle);
    const double distance_right = local_distance(curve, right_middle);
    const bool exhausted = depth >= kMaxSubdivisionDepth || left_middle <= a || right_middle >= b;
    if (std::abs(distance_left - distance_right) < e_local || exhausted) {
      const Vec2 local_foot = 0.5 * (local_point(curve, left_middle) + local_point(curve, right_middle));
      NearestPoint result;
      result.t = middle;
      result.foot = curve.origin + curve.scale * local_foot;
      result.distance = curve.scale * (curve.p - local_foot).norm();
      return result;
    }
    const double left_nearest = std::min({distance_a, distance_left, distance_middle});
    const double right_nearest = std::min({distance_middle, distance_right, distance_b});
    // The paper does not say how to break a tie (both own the middle point): the nearer child middle.
    const bool keep_left =
        left_nearest < right_nearest || (left_nearest == right_nearest && distance_left <= distance_right);
    if (keep_left) {
      b = middle;
      distance_b = distance_middle;
    } else {
      a = middle;
      distance_a = distance_middle;
    }
  }
}

}  // namespace calligraphy::detail
