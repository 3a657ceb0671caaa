#pragma once
// The devices the command line offers: the standard backends (simulated, OpenHaptics), the Phantom over
// USB and the Phantom emulator; the window commands add the mouse devices.
#include <string>

#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy::cli {

/// The program's registry, made once by main and passed to the commands that open devices: the standard
/// backends, the Phantom over USB and the emulator (the window commands add the mouse devices to it).
[[nodiscard]] DeviceRegistry make_cli_device_registry();

/// The listing of the device `name` given to `option` in `devices`, scanning only its backend. A name no
/// backend knows is a UsageError (exit 2) naming the option and the devices there are; a known device that
/// cannot be used now propagates DeviceUnavailable with the backend's reason (exit 1).
[[nodiscard]] DeviceListing find_cli_device(const DeviceRegistry& devices, const char* option,
                                            const std::string& name);

}  // namespace calligraphy::cli
