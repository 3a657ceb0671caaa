// Validation and dispatch of `nearest_point`, and the servo-path segment projection.
#include "calligraphy/model/nearest_point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "model/local_curve.hpp"
#include "model/nearest_point_methods.hpp"

namespace calligraphy {

namespace {

std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string format_point(const Vec2& v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "(%.17g, %.17g)", v.x(), v.y());
  return buffer;
}

bool usable_point(const Vec2& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::abs(v.x()) <= kMaxNearestPointCoordinate &&
         std::abs(v.y()) <= kMaxNearestPointCoordinate;
}

// Messages are built only on failure: the success path must not allocate.
[[noreturn]] void reject_point(const char* what, const Vec2& v) {
  throw InvalidArgument(std::string("nearest_point: ") + what + " = " + format_point(v) +
                        " is not finite or exceeds 1e150 in magnitude");
}

void validate(const StrokeElement& element, const Vec2& p, const NearestPointOptions& options) {
  if (element.degree < 1 || element.degree > kMaxElementDegree) {
    throw InvalidArgument("nearest_point: element degree " + std::to_string(element.degree) +
                          " is not in 1.." + std::to_string(kMaxElementDegree));
  }
  if (!usable_point(p)) reject_point("query point p", p);
  for (int i = 0; i <= element.degree; ++i) {
    const Vec2& control = element.control[static_cast<std::size_t>(i)];
    if (!usable_point(control)) reject_point(("control point " + std::to_string(i)).c_str(), control);
  }
  if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance)) {
    throw InvalidArgument("nearest_point: options.tolerance = " + format_number(options.tolerance) +
                          " must be finite and > 0");
  }
  if (options.newton_starts < 1) {
    throw InvalidArgument("nearest_point: options.newton_starts = " + std::to_string(options.newton_starts) +
                          " must be >= 1");
  }
  if (options.newton_iterations < 1) {
    throw InvalidArgument("nearest_point: options.newton_iterations = " +
                          std::to_string(options.newton_iterations) + " must be >= 1");
  }
}

// Distance from p to the box of the element's control points: a lower bound of the distance to the
// element, since a Bezier curve lies in the convex hull of its control points.
double distance_to_control_box(const StrokeElement& element, const Vec2& p) {
  Vec2 low = element.control[0];
  Vec2 high = element.control[0];
  for (int i = 1; i <= element.degree; ++i) {
    low = low.cwiseMin(element.control[static_cast<std::size_t>(i)]);
    high = high.cwiseMax(element.control[static_cast<std::size_t>(i)]);
  }
  const Vec2 outside = (low - p).cwiseMax(p - high).cwiseMax(Vec2::Zero());
  return outside.norm();
}

}  // namespace

double distance_to_elements(std::span<const StrokeElement> elements, const Vec2& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const StrokeElement& element : elements) {
    if (distance_to_control_box(element, p) >= best) continue;  // cannot be nearer
    best = std::min(best, nearest_point(element, p).distance);
  }
  return best;
}

NearestPoint nearest_point(const StrokeElement& element, const Vec2& p, const NearestPointOptions& options) {
  validate(element, p, options);
  const detail::LocalCurve curve = detail::to_local(element, p);
  switch (options.method) {
    case NearestPointMethod::newton:
      return detail::nearest_point_newton(curve, options.newton_starts, options.newton_iterations);
    case NearestPointMethod::subdivision:
      return detail::nearest_point_subdivision(curve, options.tolerance);
    case NearestPointMethod::exact:
      break;
  }
  return detail::nearest_point_exact(curve, options.tolerance);
}

NearestPoint nearest_point_on_segment(const Vec2& a, const Vec2& b, const Vec2& p) noexcept {
  NearestPoint result;
  result.t = segment_parameter(a, b, p);
  result.foot = a + result.t * (b - a);
  result.distance = ((p - a) - result.t * (b - a)).norm();
  return result;
}

}  // namespace calligraphy
