#pragma once
// The devices the command line offers: the process registry with the simulated device and the
// Phantom emulator registered.
#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry();

}  // namespace calligraphy::cli
