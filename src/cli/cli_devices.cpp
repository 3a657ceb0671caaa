#include "cli/cli_devices.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry() {
  DeviceRegistry& registry = device_registry_with_simulation();
  testing::register_emulated_phantom(registry);
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
