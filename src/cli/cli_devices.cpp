#include "cli/cli_devices.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {
namespace {

const std::vector<std::string> kEveryCommand = {"trial", "train", "session run"};

}  // namespace

DeviceRegistry make_cli_device_registry() {
  DeviceRegistry devices = standard_device_registry();
  register_phantom_usb_backends(devices);
  testing::register_emulated_phantom(devices);
  return devices;
}

std::vector<DeviceKind> device_kinds(const DeviceRegistry& devices) {
  std::vector<DeviceKind> kinds = {
      {"simulated", "simulated", "simulated", kEveryCommand,
       "the simulated device, moved by the simulated writer (train: --writer simulated)"},
      {"emulated-phantom", "emulated-phantom", "simulated", kEveryCommand,
       "the Phantom emulator behind the real Phantom driver, moved by the simulated writer (train: --writer "
       "simulated)"},
      {"mouse",
       "mouse",
       "person",
       {"train", "session run"},
       "the pointer is the pen (no force), in the trainer window"},
      {"mouse-hand",
       "mouse-hand",
       "person",
       {"train", "session run"},
       "the pointer through a simulated hand on a simulated Phantom Desktop: guidance pulls, in the trainer "
       "window"},
      {"openhaptics", "openhaptics", "person", kEveryCommand,
       "the default OpenHaptics device (a Phantom through libHD.so)"},
      {"phantom-hid:PATH", "phantom-hid", "person", kEveryCommand,
       "a Phantom over hidraw (PATH: /dev/hidrawN)"},
      {"phantom-usb:BUS-ADDRESS", "phantom-usb", "person", kEveryCommand, "a Phantom over libusb"},
  };
#ifndef CALLIGRAPHY_WITH_TRAINER
  // No window: `train` takes no device, and the pointer kinds no command.
  for (DeviceKind& kind : kinds) {
    std::erase(kind.commands, "train");
    if (kind.backend == "mouse" || kind.backend == "mouse-hand") {
      kind.commands.clear();
      kind.what += " (not in this build: no trainer window)";
    }
  }
#endif
  // A backend registered besides these (an application's own) is a device a person holds.
  for (const std::string& backend : devices.backend_names()) {
    bool known = false;
    for (const DeviceKind& kind : kinds) known = known || kind.backend == backend;
    if (!known)
      kinds.push_back({backend, backend, "person", kEveryCommand, "a device of the backend " + backend});
  }
  return kinds;
}

std::optional<bool> kind_moved_by_simulated_hand(const DeviceRegistry& devices, std::string_view name) {
  const std::string_view backend = name.substr(0, name.find(':'));
  for (const DeviceKind& kind : device_kinds(devices)) {
    if (kind.backend == backend) return kind.writer == "simulated";
  }
  return std::nullopt;
}

DeviceListing find_cli_device(const DeviceRegistry& devices, const std::string& option,
                              const std::string& name) {
  try {
    return devices.find(name);
  } catch (const DeviceUnavailable&) {
    throw;
  } catch (const DeviceNotFound& e) {
    if (name == "mouse" || name == "mouse-hand") {  // the window's devices: only its commands have a pointer
      throw UsageError((option.empty() ? "" : option + " ") + name +
                       ": the pointer devices are taken by commands with the trainer window (train, session "
                       "run); `calligraphy devices` lists the commands that take each device");
    }
    // The registry's message names the device and the ones there are: said once.
    throw UsageError((option.empty() ? "" : option + ": ") + e.what());
  }
}

}  // namespace calligraphy::cli
