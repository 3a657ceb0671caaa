#include "cli/cli_devices.hpp"

#include <algorithm>

#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry() {
  DeviceRegistry& registry = device_registry_with_simulation();
  testing::register_emulated_phantom(registry);
  return registry;
}

void fit_default_stiffness(ForceLawParameters& force, const DeviceInfo& device) {
  const double limit = device.max_stiffness_n_per_m;
  if (!(limit > 0.0)) return;  // 0: the device states no limit
  const ForceLawParameters defaults;
  if (force.paper_stiffness_n_per_m == defaults.paper_stiffness_n_per_m) {
    force.paper_stiffness_n_per_m = std::min(force.paper_stiffness_n_per_m, limit);
  }
  if (force.guidance_stiffness_n_per_m == defaults.guidance_stiffness_n_per_m) {
    force.guidance_stiffness_n_per_m = std::min(force.guidance_stiffness_n_per_m, limit);
  }
}

}  // namespace calligraphy::cli
