#include "cli/cli_devices.hpp"

#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry() {
  DeviceRegistry& registry = device_registry_with_simulation();
  testing::register_emulated_phantom(registry);
  return registry;
}

}  // namespace calligraphy::cli
