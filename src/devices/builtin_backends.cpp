#include "devices/builtin_backends.hpp"

namespace calligraphy {

void register_builtin_device_backends(DeviceRegistry& registry) {
  // The simulated device (lead's SimulatedDevice) belongs first in the list, e.g.:
  //   registry.register_device("simulated", simulated_info(), [] { return
  //   std::make_unique<SimulatedDevice>(); });
#if defined(CALLIGRAPHY_WITH_PHANTOM)
  phantom::register_backends(registry);
#endif
#if defined(CALLIGRAPHY_WITH_OPENHAPTICS)
  openhaptics::register_backend(registry);
#endif
  (void)registry;
}

}  // namespace calligraphy
