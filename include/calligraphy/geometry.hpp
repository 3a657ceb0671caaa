#pragma once
/// \file geometry.hpp
/// Vector types. Model coordinates are in the data's units (hanzi-writer-data's 1024 box, y up);
/// scene and device coordinates are metres, with the paper plane at z = z0 and +z out of the paper.

#include <Eigen/Core>

namespace calligraphy {

using Vec2 = Eigen::Vector2d;  ///< a point or vector in a plane (model units or m)
using Vec3 = Eigen::Vector3d;  ///< a point or vector in device space (m, m/s or N)

/// True when every component is finite (no NaN, no infinity).
template <typename Derived>
[[nodiscard]] bool all_finite(const Eigen::MatrixBase<Derived>& v) {
  return v.allFinite();
}

}  // namespace calligraphy
