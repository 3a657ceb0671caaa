#include "devices/builtin_backends.hpp"

#include <memory>

#include "calligraphy/simulated_device.hpp"

namespace calligraphy {

void register_builtin_device_backends(DeviceRegistry& registry) {
  // The simulated device is always there, first in the list.
  registry.register_device("simulated", phantom_desktop_info(), [] { return std::make_unique<SimulatedDevice>(); });
#if defined(CALLIGRAPHY_WITH_PHANTOM)
  phantom::register_backends(registry);
#endif
#if defined(CALLIGRAPHY_WITH_OPENHAPTICS)
  openhaptics::register_backend(registry);
#endif
  (void)registry;
}

}  // namespace calligraphy
