#include "cli/cli_devices.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry() {
  // The program's one registry: built once; the window commands add the trainer's pointer devices.
  static DeviceRegistry registry = [] {
    DeviceRegistry built = standard_device_registry();
    register_phantom_usb_backends(built);
    testing::register_emulated_phantom(built);
    return built;
  }();
  return registry;
}

DeviceListing find_cli_device(const char* option, const std::string& name) {
  try {
    return cli_device_registry().find(name);
  } catch (const DeviceUnavailable&) {
    throw;
  } catch (const DeviceNotFound& e) {
    throw UsageError(std::string(option) + ": unknown device '" + name + "': " + e.what());
  }
}

}  // namespace calligraphy::cli
