#pragma once
// The devices the command line offers: the standard backends (simulated, OpenHaptics), the Phantom over
// USB and the Phantom emulator; the window commands add the mouse devices.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy::cli {

/// The program's registry, made once by main and passed to the commands that open devices: the standard
/// backends, the Phantom over USB and the emulator (the window commands add the mouse devices to it).
[[nodiscard]] DeviceRegistry make_cli_device_registry();

/// What a kind of device is and which commands take it with --device (`calligraphy devices`, docs/cli.md).
/// The commands are those that open a device by name: `trial`, `train` and `session run` (`session resume`
/// goes on on the session's device).
struct DeviceKind {
  std::string name;     ///< what --device takes, or its pattern ("phantom-hid:PATH")
  std::string backend;  ///< the registry backend that makes it (the window adds "mouse" and "mouse-hand")
  std::string writer;   ///< who writes with it: "simulated" or "person"
  std::vector<std::string> commands;
  std::string what;
};

/// Every kind of device the commands take: the registry's backends, the emulator and the window's pointer
/// devices; a backend registered besides these is a device a person holds.
[[nodiscard]] std::vector<DeviceKind> device_kinds(const DeviceRegistry& devices);

/// Whether the simulated writer moves the devices of the kind `name` belongs to (its backend: the name up to
/// a ':'), known without scanning or opening one: so a writer or a pacing a device cannot have is refused as
/// the usage error it is also when the device cannot be used now. Empty for a name of no kind.
[[nodiscard]] std::optional<bool> kind_moved_by_simulated_hand(const DeviceRegistry& devices,
                                                               std::string_view name);

/// The listing of the device `name` given to `option` in `devices`, scanning only its backend. A name no
/// backend knows is a UsageError (exit 2) naming the option (when one is given: a record names its own
/// place) and the devices there are; a known device that cannot be used now propagates DeviceUnavailable
/// with the backend's reason (exit 1).
[[nodiscard]] DeviceListing find_cli_device(const DeviceRegistry& devices, const std::string& option,
                                            const std::string& name);

}  // namespace calligraphy::cli
