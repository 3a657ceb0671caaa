#pragma once
// A device's limits (DeviceInfo) as a JSON object: every field in SI units, by its name. `calligraphy devices
// --json` and a study trial record's `device.info` both write it, so they name and give the same fields.
// Internal to the report module and the modules above it.
#include <nlohmann/json.hpp>

#include "calligraphy/core/device_types.hpp"

namespace calligraphy::report_detail {

/// `model`, `manufacturer`, `max_force_n`, `max_continuous_force_n`, `max_stiffness_n_per_m`,
/// `max_damping_n_s_per_m`, `intrinsic_damping_n_s_per_m`, `workspace_radius_m`, `workspace_size_m` [x, y,
/// z].
nlohmann::json device_info_object(const DeviceInfo& info);

}  // namespace calligraphy::report_detail
