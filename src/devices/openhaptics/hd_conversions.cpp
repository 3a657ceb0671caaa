#include "devices/openhaptics/hd_conversions.hpp"

#include <algorithm>

namespace calligraphy::openhaptics {

DeviceInfo info_from_hd_nominals(const char* model, const char* vendor, double max_force_n,
                                 double max_continuous_force_n, double stiffness_n_per_mm,
                                 double damping_n_s_per_mm, const std::array<double, 6>& usable_mm) {
  DeviceInfo info;
  info.model = model != nullptr && *model != '\0' ? model : "OpenHaptics device";
  info.manufacturer = vendor != nullptr && *vendor != '\0' ? vendor : "unknown (via OpenHaptics)";
  info.max_force_n = max_force_n;
  info.max_continuous_force_n = max_continuous_force_n;
  info.max_stiffness_n_per_m = stiffness_n_per_mm * 1e3;
  info.max_damping_n_s_per_m = damping_n_s_per_mm * 1e3;
  const double extent_x = usable_mm[3] - usable_mm[0];
  const double extent_y = usable_mm[4] - usable_mm[1];  // HD y: up
  const double extent_z = usable_mm[5] - usable_mm[2];  // HD z: towards the user
  info.workspace_size_m = Vec3(extent_x, extent_z, extent_y) * 1e-3;
  info.workspace_radius_m = 0.5 * info.workspace_size_m.minCoeff();
  return info;
}

}  // namespace calligraphy::openhaptics
