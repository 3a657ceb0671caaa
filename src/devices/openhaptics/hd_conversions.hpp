#pragma once
// Units and frames between HDAPI and this library. HDAPI: millimetres, x right, y up, z towards the
// user (OpenHaptics convention). Library (haptic_device.hpp): metres, x right, y away from the writer,
// z up. So device = (x, -z, y) / 1000 for positions and velocities; forces go the other way in newtons.
#include <array>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy::openhaptics {

/// HD position [mm] or velocity [mm/s] -> device frame [m] or [m/s].
[[nodiscard]] inline Vec3 hd_mm_to_device_m(const std::array<double, 3>& hd_mm) noexcept {
  return Vec3(hd_mm[0], -hd_mm[2], hd_mm[1]) * 1e-3;
}

/// Device-frame force [N] -> HD_CURRENT_FORCE [N] in HD axes.
[[nodiscard]] inline std::array<double, 3> device_force_to_hd(const Vec3& force_n) noexcept {
  return {force_n.x(), force_n.z(), -force_n.y()};
}

/// DeviceInfo from HDAPI nominal values: forces [N], stiffness [N/mm], damping [N s/mm] and the usable
/// workspace [mm] (min x y z, max x y z in HD axes). The radius is half the smallest extent.
[[nodiscard]] DeviceInfo info_from_hd_nominals(const char* model, const char* vendor, double max_force_n,
                                               double max_continuous_force_n, double stiffness_n_per_mm,
                                               double damping_n_s_per_mm,
                                               const std::array<double, 6>& usable_mm);

}  // namespace calligraphy::openhaptics
