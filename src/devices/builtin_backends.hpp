#pragma once
// Registration of the device backends compiled into this build. The optional folders
// src/devices/phantom and src/devices/openhaptics define CALLIGRAPHY_WITH_PHANTOM and
// CALLIGRAPHY_WITH_OPENHAPTICS on the library target when they are built.
#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy {

/// Called once by device_registry(): the hardware backends built into this library. Simulated and
/// emulated devices live in modules above this one and register themselves (simulated_device.hpp,
/// calligraphy/testing/emulated_phantom.hpp).
void register_builtin_device_backends(DeviceRegistry& registry);

namespace phantom {
void register_backends(DeviceRegistry& registry);  // src/devices/phantom/phantom_backends.cpp
}
namespace openhaptics {
void register_backend(DeviceRegistry& registry);  // src/devices/openhaptics/openhaptics_backend.cpp
}

}  // namespace calligraphy
