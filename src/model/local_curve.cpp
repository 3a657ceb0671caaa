#include "model/local_curve.hpp"

#include <algorithm>
#include <cmath>

namespace calligraphy::detail {

namespace {
double max_abs_component(const Vec2& v) { return std::max(std::abs(v.x()), std::abs(v.y())); }
}  // namespace

LocalCurve to_local(const StrokeElement& element, const Vec2& p) noexcept {
  LocalCurve curve;
  curve.degree = element.degree;
  curve.origin = element.control[0];
  // The extent covers the control points and the query point, so local coordinates stay within
  // [-1, 1] and squared distances cannot overflow even for a far point and a tiny element.
  double extent = max_abs_component(p - curve.origin);
  for (int i = 1; i <= element.degree; ++i) {
    extent = std::max(extent, max_abs_component(element.control[static_cast<std::size_t>(i)] - curve.origin));
  }
  int exponent = 0;
  if (extent > 0.0) std::frexp(extent, &exponent);  // extent = m * 2^exponent, m in [0.5, 1)
  curve.scale = std::ldexp(1.0, exponent);
  // 2^-exponent overflows for an extent below 2^-1022 (subnormal): such an extent is scaled by ldexp, which
  // is exact for each coordinate; every other extent by one multiplication.
  const bool subnormal_extent = exponent < -1021;
  const double inverse_scale = subnormal_extent ? 0.0 : std::ldexp(1.0, -exponent);
  const auto to_unit = [&](const Vec2& v) {
    return subnormal_extent ? Vec2(std::ldexp(v.x(), -exponent), std::ldexp(v.y(), -exponent))
                            : Vec2(v * inverse_scale);
  };
  for (int i = 0; i <= element.degree; ++i) {
    const auto index = static_cast<std::size_t>(i);
    curve.q[index] = to_unit(element.control[index] - curve.origin);
  }
  curve.p = to_unit(p - curve.origin);
  return curve;
}

Vec2 local_point(const LocalCurve& curve, double t) noexcept {
  std::array<Vec2, kMaxElementDegree + 1> r = curve.q;
  for (int level = 1; level <= curve.degree; ++level) {
    for (int i = 0; i <= curve.degree - level; ++i) {
      const auto index = static_cast<std::size_t>(i);
      r[index] = (1.0 - t) * r[index] + t * r[index + 1];  // exact at t = 0 and 1
    }
  }
  return r[0];
}

CurveJet local_jet(const LocalCurve& curve, double t) noexcept {
  const int n = curve.degree;
  std::array<Vec2, kMaxElementDegree + 1> r = curve.q;
  CurveJet jet;
  // After level n-2 the three remaining points span B''; after level n-1 the two span B'.
  for (int level = 1; level <= n; ++level) {
    if (level == n - 1) jet.second = static_cast<double>(n * (n - 1)) * (r[2] - 2.0 * r[1] + r[0]);
    if (level == n) jet.first = static_cast<double>(n) * (r[1] - r[0]);
    for (int i = 0; i <= n - level; ++i) {
      const auto index = static_cast<std::size_t>(i);
      r[index] = (1.0 - t) * r[index] + t * r[index + 1];  // exact at t = 0 and 1
    }
  }
  jet.point = r[0];
  return jet;
}

double local_squared_distance(const LocalCurve& curve, double t) noexcept {
  return (local_point(curve, t) - curve.p).squaredNorm();
}

NearestPoint local_result(const LocalCurve& curve, double t) noexcept {
  const Vec2 local_foot = local_point(curve, t);
  NearestPoint result;
  result.t = t;
  result.foot = curve.origin + curve.scale * local_foot;
  result.distance = curve.scale * (curve.p - local_foot).norm();
  return result;
}

NearestPoint local_segment_nearest(const LocalCurve& curve) noexcept {
  const Vec2 edge = curve.q[1];  // q0 is the origin
  const double length_squared = edge.squaredNorm();
  double t = 0.0;
  if (length_squared > 0.0) t = std::clamp(curve.p.dot(edge) / length_squared, 0.0, 1.0);
  NearestPoint result;
  result.t = t;
  result.foot = curve.origin + curve.scale * (t * edge);
  result.distance = curve.scale * (curve.p - t * edge).norm();
  return result;
}

}  // namespace calligraphy::detail
