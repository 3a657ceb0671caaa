// The exact method: all stationary points of |B(t) - P|^2 on [0, 1], after Schneider, "Solving the
// Nearest-Point-on-Curve Problem" (Graphics Gems, 1990), with an interval-width stopping rule
// instead of his flatness test, and a bracketed Newton refinement of each isolated root.
#include <algorithm>
#include <cmath>
#include <limits>

#include "model/bernstein.hpp"
#include "model/nearest_point_methods.hpp"

namespace calligraphy::detail {

namespace {

// f(t) = (B(t) - P).B'(t) / n in Bernstein form of degree 2n - 1. With B - P = sum_i (q_i - P) b_{i,n}
// and B'/n = sum_j (q_{j+1} - q_j) b_{j,n-1}, the product rule of Bernstein bases
// b_{i,n} b_{j,n-1} = C(n,i) C(n-1,j) / C(2n-1,i+j) b_{i+j,2n-1} gives the coefficients.
// `noise` bounds their rounding error (and that of every subdivision of them).
struct DistanceDerivative {
  BernsteinPolynomial f;
  double noise;
};

DistanceDerivative distance_derivative(const LocalCurve& curve) noexcept {
  const int n = curve.degree;
  DistanceDerivative result{};
  result.f.degree = 2 * n - 1;
  std::array<double, kMaxBernsteinDegree + 1> magnitude{};
  for (int i = 0; i <= n; ++i) {
    const Vec2 offset = curve.q[static_cast<std::size_t>(i)] - curve.p;
    for (int j = 0; j < n; ++j) {
      const Vec2 edge = curve.q[static_cast<std::size_t>(j + 1)] - curve.q[static_cast<std::size_t>(j)];
      const double weight = binomial(n, i) * binomial(n - 1, j) / binomial(2 * n - 1, i + j);
      const auto k = static_cast<std::size_t>(i + j);
      result.f.c[k] += weight * offset.dot(edge);
      magnitude[k] += weight * offset.norm() * edge.norm();
    }
  }
  // Rounding of the sums of products and of up to kMaxDepth de Casteljau levels, with margin.
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  result.noise = 64.0 * kEpsilon * *std::max_element(magnitude.begin(), magnitude.end());
  return result;
}

// Sign of the first coefficient above `noise`, from the start (`from_start`) or from the end.
double end_sign(const BernsteinPolynomial& f, double noise, bool from_start) noexcept {
  for (int i = 0; i <= f.degree; ++i) {
    const double value = f.c[static_cast<std::size_t>(from_start ? i : f.degree - i)];
    if (std::abs(value) > noise) return value > 0.0 ? 1.0 : -1.0;
  }
  return 0.0;
}

// The single root of `f` inside its interval (a, b) (f has one sign change there), to `t_tolerance`.
// Newton from the regula-falsi point, falling back to bisection whenever a step leaves the bracket
// (a converged step may land on the bracket's end: it is accepted). f may vanish at an end (B' = 0
// at a cusp or at coincident control points, or a root at a split point): next to that end it has
// the sign of the nearest coefficient above the noise.
double refine_single_root(const BernsteinPolynomial& f, double noise, double a, double b,
                          double t_tolerance) noexcept {
  const double first = f.c[0];
  const double last = f.c[static_cast<std::size_t>(f.degree)];
  const double sign_at_low = end_sign(f, noise, true);
  const double width = b - a;
  const double u_tolerance = t_tolerance / width;
  double low = 0.0;   // f has sign `sign_at_low` on (0, root)
  double high = 1.0;  // and the opposite sign on (root, 1)
  const bool ends_clear = std::abs(first) > noise && std::abs(last) > noise;
  double u = ends_clear ? first / (first - last) : 0.5;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const ValueAndSlope value = evaluate(f, u);
    if (value.value == 0.0) break;
    if ((value.value > 0.0) == (sign_at_low > 0.0)) {
      low = u;
    } else {
      high = u;
    }
    const double newton = u - value.value / value.slope;
    if (newton >= low && newton <= high) {  // false for a zero slope (NaN or inf)
      const double step = std::abs(newton - u);
      u = newton;
      if (step <= u_tolerance) break;  // converged quadratically: u is far more accurate than the step
    } else {
      u = 0.5 * (low + high);
      if (high - low <= u_tolerance) break;
    }
  }
  return a + u * width;
}

// No default member initializers: see BernsteinPolynomial.
struct PendingInterval {
  BernsteinPolynomial f;
  double a;
  double b;
  int depth;
};

// True when no point of the interval can be nearer than `best_squared_distance` (branch and bound).
// d/dt |B - P|^2 = 2n f, so |B(t) - P|^2 = |B(a) - P|^2 + 2n (b - a) * integral of f over [0, u]; the
// Bernstein coefficients of that integral are the prefix sums of f's divided by degree + 1, and
// the integral is at least their minimum (convex hull property).
bool cannot_beat(const LocalCurve& curve, const PendingInterval& interval, double noise,
                 double best_squared_distance) noexcept {
  const int m = interval.f.degree;
  double prefix = 0.0;
  double lowest = 0.0;
  for (int i = 0; i <= m; ++i) {
    prefix += interval.f.c[static_cast<std::size_t>(i)];
    lowest = std::min(lowest, prefix);
  }
  const double start = local_squared_distance(curve, interval.a);
  const double factor = 2.0 * curve.degree * (interval.b - interval.a) / (m + 1);
  // Rounding of the start distance and of the coefficients, with a margin of 2.
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  const double slack = 16.0 * kEpsilon * start + 2.0 * factor * (m + 1) * noise;
  return start + factor * lowest - slack > best_squared_distance;
}

// Deepest subdivision: the interval is then below 2^-kMaxDepth, under any useful tolerance.
constexpr int kMaxDepth = 60;

}  // namespace

NearestPoint nearest_point_exact(const LocalCurve& curve, double t_tolerance) noexcept {
  if (curve.degree == 1) return local_segment_nearest(curve);
  NearestCandidate best(curve, 0.0);
  best.offer(curve, 1.0);

  // Depth-first, left half first; at most one pending interval per level plus the current one.
  std::array<PendingInterval, kMaxDepth + 2> stack;
  const DistanceDerivative derivative = distance_derivative(curve);
  const double noise = derivative.noise;
  stack[0] = {derivative.f, 0.0, 1.0, 0};
  int size = 1;
  while (size > 0) {
    const PendingInterval interval = stack[static_cast<std::size_t>(--size)];
    // A root at an end (a split point, e.g. a cusp at t = 0.5) is inside no interval.
    if (std::abs(interval.f.c[0]) <= noise) best.offer(curve, interval.a);
    if (negligible(interval.f, noise)) {
      // f vanishes over the interval within rounding (a zero-length element, or a tiny interval
      // at a centre of curvature): the distance is constant there, any point will do.
      best.offer(curve, 0.5 * (interval.a + interval.b));
      continue;
    }
    const int variations = sign_variations(interval.f, noise);
    if (variations == 0) continue;
    // One root where f goes from + to -: a local maximum of the distance.
    if (variations == 1 && end_sign(interval.f, noise, true) > 0.0) continue;
    if (cannot_beat(curve, interval, noise, best.squared_distance)) continue;
    if (variations == 1) {
      best.offer(curve, refine_single_root(interval.f, noise, interval.a, interval.b, t_tolerance));
      continue;
    }
    const double middle = 0.5 * (interval.a + interval.b);
    const bool too_narrow = interval.b - interval.a <= t_tolerance || middle <= interval.a ||
                            middle >= interval.b || interval.depth >= kMaxDepth;
    if (too_narrow) {
      // A multiple root (centre of curvature) or clustered roots: any point of the tiny interval
      // is as near as the root within rounding.
      best.offer(curve, middle);
      continue;
    }
    PendingInterval left;
    PendingInterval right;
    split_at_middle(interval.f, left.f, right.f);
    left.a = interval.a;
    left.b = middle;
    right.a = middle;
    right.b = interval.b;
    left.depth = right.depth = interval.depth + 1;
    stack[static_cast<std::size_t>(size++)] = right;
    stack[static_cast<std::size_t>(size++)] = left;
  }
  return local_result(curve, best.t);
}

}  // namespace calligraphy::detail
