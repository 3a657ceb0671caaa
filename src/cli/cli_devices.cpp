#include "cli/cli_devices.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

DeviceRegistry make_cli_device_registry() {
  DeviceRegistry devices = standard_device_registry();
  register_phantom_usb_backends(devices);
  testing::register_emulated_phantom(devices);
  return devices;
}

DeviceListing find_cli_device(const DeviceRegistry& devices, const char* option, const std::string& name) {
  try {
    return devices.find(name);
  } catch (const DeviceUnavailable&) {
    throw;
  } catch (const DeviceNotFound& e) {
    if (name == "mouse" || name == "mouse-hand") {  // the window's devices: only its commands have a pointer
      throw UsageError(std::string(option) + " " + name +
                       ": the pointer devices are taken by commands with the trainer window (train, session "
                       "run); `calligraphy devices` lists the commands that take each device");
    }
    // The registry's message names the device and the ones there are: said once.
    throw UsageError(std::string(option) + ": " + e.what());
  }
}

}  // namespace calligraphy::cli
