#pragma once
// The backends of this module whose code lives in optional folders: src/devices/openhaptics defines
// CALLIGRAPHY_WITH_OPENHAPTICS on the library target when it is built.
#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy::openhaptics {
void register_backend(DeviceRegistry& registry);  // src/devices/openhaptics/openhaptics_backend.cpp
}  // namespace calligraphy::openhaptics
