#include "devices/builtin_backends.hpp"

#include <memory>

namespace calligraphy {

void register_builtin_device_backends(DeviceRegistry& registry) {
#if defined(CALLIGRAPHY_WITH_PHANTOM)
  phantom::register_backends(registry);
#endif
#if defined(CALLIGRAPHY_WITH_OPENHAPTICS)
  openhaptics::register_backend(registry);
#endif
  (void)registry;
}

}  // namespace calligraphy
