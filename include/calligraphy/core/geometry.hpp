#pragma once
/// \file geometry.hpp
/// Vector types. Model coordinates are in the data's units (hanzi-writer-data's 1024 box, y up);
/// scene and device coordinates are metres, with the paper plane at z = z0 and +z out of the paper.

#include <Eigen/Core>
#include <algorithm>

namespace calligraphy {

using Vec2 = Eigen::Vector2d;  ///< a point or vector in a plane (model units or m)
using Vec3 = Eigen::Vector3d;  ///< a point or vector in device space (m, m/s or N)

/// True when every component is finite (no NaN, no infinity).
template <typename Derived>
[[nodiscard]] bool all_finite(const Eigen::MatrixBase<Derived>& v) {
  return v.allFinite();
}

/// Parameter t in [0, 1] of the point of segment [a, b] nearest to p (0 for a zero-length segment).
/// Orthogonal projection, clamped: t = clamp((p - a).(b - a) / |b - a|^2, 0, 1).
[[nodiscard]] inline double segment_parameter(const Vec2& a, const Vec2& b, const Vec2& p) noexcept {
  const Vec2 edge = b - a;
  const double length_squared = edge.squaredNorm();
  if (!(length_squared > 0.0)) return 0.0;
  return std::clamp((p - a).dot(edge) / length_squared, 0.0, 1.0);
}

/// Distance from p to the segment [a, b], in the units of the points.
[[nodiscard]] inline double distance_to_segment(const Vec2& a, const Vec2& b, const Vec2& p) noexcept {
  return ((p - a) - segment_parameter(a, b, p) * (b - a)).norm();
}

}  // namespace calligraphy
