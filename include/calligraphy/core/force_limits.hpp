#pragma once
/// \file force_limits.hpp
/// Force safety helpers shared by device implementations.

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// `force_n` [N] scaled down to at most `max_force_n` [N] in magnitude, direction preserved.
/// A non-finite force or a non-positive limit gives zero force.
[[nodiscard]] inline Vec3 clamp_force_magnitude(const Vec3& force_n, double max_force_n) noexcept {
  if (!force_n.allFinite() || !(max_force_n > 0.0)) return Vec3::Zero();
  const double magnitude = force_n.norm();
  if (magnitude <= max_force_n) return force_n;
  return force_n * (max_force_n / magnitude);
}

}  // namespace calligraphy
