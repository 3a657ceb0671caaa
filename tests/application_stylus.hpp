#pragma once
// The limits of an application's own stylus, as the public-header rounds give their device: a desktop-class
// arm (3 N peak, 1 N continuous, 1000 N/m, 5 N s/m, a 16 x 12 x 12 cm workspace) named `model`.
#include <string>
#include <utility>

#include "calligraphy/core/device_types.hpp"

namespace calligraphy::testing {

inline DeviceInfo application_stylus_info(std::string model) {
  DeviceInfo info;
  info.model = std::move(model);
  info.max_force_n = 3.0;
  info.max_continuous_force_n = 1.0;
  info.max_stiffness_n_per_m = 1000.0;
  info.max_damping_n_s_per_m = 5.0;
  info.workspace_radius_m = 0.08;
  info.workspace_size_m = Vec3(0.16, 0.12, 0.12);
  return info;
}

}  // namespace calligraphy::testing
