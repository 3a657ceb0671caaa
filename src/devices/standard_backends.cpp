#include "devices/standard_backends.hpp"

#include "calligraphy/devices/simulated_device.hpp"

namespace calligraphy {

void register_standard_device_backends(DeviceRegistry& registry) {
  register_simulated_device(registry);
#if defined(CALLIGRAPHY_WITH_OPENHAPTICS)
  openhaptics::register_backend(registry);
#endif
}

DeviceRegistry standard_device_registry() {
  DeviceRegistry registry;
  register_standard_device_backends(registry);
  return registry;
}

}  // namespace calligraphy
