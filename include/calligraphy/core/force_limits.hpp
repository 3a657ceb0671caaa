#pragma once
/// \file force_limits.hpp
/// Force safety helpers shared by device implementations.

#include <cmath>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// `force_n` [N] scaled down to at most `max_force_n` [N] in magnitude, direction preserved.
/// A non-finite force or a non-positive limit gives zero force; a finite force of any size (1e308 N) is
/// scaled, never zeroed.
[[nodiscard]] inline Vec3 clamp_force_magnitude(const Vec3& force_n, double max_force_n) noexcept {
  if (!force_n.allFinite() || !(max_force_n > 0.0)) return Vec3::Zero();
  const double magnitude = force_n.norm();
  if (magnitude <= max_force_n) return force_n;
  if (!std::isfinite(magnitude)) {  // finite components whose squares overflow (1e308 N): scale them first
    const Vec3 scaled = force_n / force_n.cwiseAbs().maxCoeff();
    return scaled * (max_force_n / scaled.norm());
  }
  return force_n * (max_force_n / magnitude);
}

}  // namespace calligraphy
