#pragma once
// The nearest-point methods on a curve already in its local frame. No validation, no exceptions:
// `nearest_point` validates, and the tracker calls these on the servo path.
#include <algorithm>
#include <limits>

#include "calligraphy/model/nearest_point.hpp"
#include "model/local_curve.hpp"

namespace calligraphy::detail {

/// Keeps the nearest of the candidate parameters offered; among equally near ones (within the
/// rounding of the squared distance) the smallest t, so that ties do not depend on rounding.
struct NearestCandidate {
  double t = 0.0;
  double squared_distance = 0.0;  ///< local units

  NearestCandidate(const LocalCurve& curve, double first_t) noexcept
      : t(first_t), squared_distance(local_squared_distance(curve, first_t)) {}
  void offer(const LocalCurve& curve, double candidate_t) noexcept {
    const double d2 = local_squared_distance(curve, candidate_t);
    const double tie = 8.0 * std::numeric_limits<double>::epsilon() * std::max(d2, squared_distance);
    if (d2 < squared_distance - tie || (d2 <= squared_distance + tie && candidate_t < t)) {
      squared_distance = d2;
      t = candidate_t;
    }
  }
};

/// Global minimum: Bernstein root isolation of (B-P).B' plus both endpoints. `t_tolerance` > 0.
NearestPoint nearest_point_exact(const LocalCurve& curve, double t_tolerance) noexcept;

/// Newton from `starts` evenly spaced starts, `iterations` each, plus both endpoints.
NearestPoint nearest_point_newton(const LocalCurve& curve, int starts, int iterations) noexcept;

/// The paper's greedy subdivision (section 4.3.2) with stopping distance `e` (element units).
NearestPoint nearest_point_subdivision(const LocalCurve& curve, double e) noexcept;

/// One Newton step on f(t) = (B(t)-P).B'(t) from t, clamped to [0, 1]; returns t unchanged where
/// f'(t) = |B'|^2 + (B-P).B'' <= 0 (P beyond the centre of curvature: the step would climb).
double newton_step(const LocalCurve& curve, double t) noexcept;

}  // namespace calligraphy::detail
