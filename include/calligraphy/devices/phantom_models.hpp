#pragma once
/// \file phantom_models.hpp
/// DeviceInfo of the Phantom family, SI units.
/// Peak force, stiffness, damping and workspace radius: CHAI3D's per-model values (CPhantomDevices.cpp).
/// Continuous force and workspace box: the vendor's Phantom Omni and Desktop datasheets, as recalled
/// (not re-checked against the datasheets here).

#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// Phantom Omni: 3.3 N, 0.88 N continuous, 700 N/m, 5 N s/m, 0.10 m radius, 0.16 x 0.12 x 0.07 m.
[[nodiscard]] DeviceInfo phantom_omni_info();
/// Phantom Desktop: 7.9 N, 1.75 N continuous, 1000 N/m, 5 N s/m, 0.10 m radius, 0.16 x 0.12 x 0.12 m.
[[nodiscard]] DeviceInfo phantom_desktop_info();
/// Geomagic / 3D Systems Touch: 3.3 N, 0.88 N continuous, 400 N/m, 4 N s/m, 0.075 m radius,
/// 0.16 x 0.12 x 0.07 m.
[[nodiscard]] DeviceInfo touch_info();

}  // namespace calligraphy
