#include "calligraphy/model/nearest_point_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "model/local_curve.hpp"
#include "model/nearest_point_methods.hpp"

namespace calligraphy {

namespace {

constexpr double kMaxCoordinate = 1e150;  // as nearest_point: squared distances must not overflow
// Step in t where the distance is concave (P beyond the centre of curvature) and Newton would climb.
constexpr double kConcaveStep = 1.0 / 32.0;
constexpr int kMaxHalvings = 8;

bool usable(const Vec2& v) noexcept {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::abs(v.x()) <= kMaxCoordinate &&
         std::abs(v.y()) <= kMaxCoordinate;
}

bool usable(const StrokeElement& element) noexcept {
  if (element.degree < 1 || element.degree > kMaxElementDegree) return false;
  for (int i = 0; i <= element.degree; ++i) {
    if (!usable(element.control[static_cast<std::size_t>(i)])) return false;
  }
  return true;
}

// Damped Newton descent on |B(t) - P|^2 from t: each accepted step decreases the distance, so the
// parameter stays in the basin of the tracked minimum instead of jumping to a far root of f.
double descend(const detail::LocalCurve& curve, double t, int iterations) noexcept {
  double squared_distance = detail::local_squared_distance(curve, t);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    const detail::CurveJet jet = detail::local_jet(curve, t);
    const Vec2 offset = jet.point - curve.p;
    const double f = offset.dot(jet.first);  // half the derivative of the squared distance
    if (f == 0.0) break;
    const double slope = jet.first.squaredNorm() + offset.dot(jet.second);
    double step = slope > 0.0 ? -f / slope : (f > 0.0 ? -kConcaveStep : kConcaveStep);
    bool improved = false;
    for (int halving = 0; halving < kMaxHalvings && !improved; ++halving, step *= 0.5) {
      const double next = std::clamp(t + step, 0.0, 1.0);
      const double next_squared_distance = detail::local_squared_distance(curve, next);
      if (next_squared_distance < squared_distance) {
        t = next;
        squared_distance = next_squared_distance;
        improved = true;
      }
    }
    if (!improved) break;
  }
  return t;
}

std::string describe(const char* name, double value) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "NearestPointTracker: options.%s = %.17g", name, value);
  return buffer;
}

}  // namespace

NearestPointTracker::NearestPointTracker(const NearestPointTrackerOptions& options) : options_(options) {
  if (options.global_check_period < 1) {
    throw InvalidArgument(describe("global_check_period", options.global_check_period) + " must be >= 1");
  }
  if (!(options.switch_hysteresis_m >= 0.0) || !std::isfinite(options.switch_hysteresis_m)) {
    throw InvalidArgument(describe("switch_hysteresis_m", options.switch_hysteresis_m) +
                          " must be finite and >= 0 (m)");
  }
  if (options.newton_iterations < 1) {
    throw InvalidArgument(describe("newton_iterations", options.newton_iterations) + " must be >= 1");
  }
  if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance)) {
    throw InvalidArgument(describe("tolerance", options.tolerance) + " must be finite and > 0");
  }
}

void NearestPointTracker::reset() noexcept {
  tracking_ = false;
  ticks_since_global_ = 0;
}

NearestPoint NearestPointTracker::update(const StrokeElement& element, const Vec2& p) noexcept {
  if (!usable(p) || !usable(element)) return current_;
  const detail::LocalCurve curve = detail::to_local(element, p);
  if (element.degree == 1) {
    current_ = detail::local_segment_nearest(curve);  // closed form: nothing to track
  } else if (!tracking_) {
    current_ = detail::nearest_point_exact(curve, options_.tolerance);
    ticks_since_global_ = 0;
  } else {
    NearestPoint tracked =
        detail::local_result(curve, descend(curve, current_.t, options_.newton_iterations));
    if (++ticks_since_global_ >= options_.global_check_period) {
      ticks_since_global_ = 0;
      const NearestPoint global = detail::nearest_point_exact(curve, options_.tolerance);
      if (global.distance < tracked.distance - options_.switch_hysteresis_m) tracked = global;
    }
    current_ = tracked;
  }
  tracking_ = true;
  return current_;
}

}  // namespace calligraphy
