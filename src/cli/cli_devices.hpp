#pragma once
// The devices the command line offers: the process registry with the simulated device and the
// Phantom emulator registered.
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/render/force_law.hpp"

namespace calligraphy::cli {

DeviceRegistry& cli_device_registry();

/// Caps the force law's default stiffnesses (the paper's K_en = 800 N/m, K_et = 400 N/m) at the device's
/// stable maximum, `DeviceInfo::max_stiffness_n_per_m` (the Phantom Omni's 700 N/m), so that a command's
/// defaults never draw the renderer's over-limit warning. A stiffness that differs from the default (set
/// on purpose, e.g. by a study protocol) is kept as it is, and warned about.
void fit_default_stiffness(ForceLawParameters& force, const DeviceInfo& device);

}  // namespace calligraphy::cli
