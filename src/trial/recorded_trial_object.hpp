#pragma once
// The specification object of a trial record (recorded_trial.hpp) as JSON, for the record's writer. Internal.
#include <nlohmann/json.hpp>

#include "calligraphy/trial/recorded_trial.hpp"

namespace calligraphy::trial_detail {

/// `recorded_trial_json`'s object.
nlohmann::json recorded_trial_object(const RecordedTrial& recorded);

/// A simulated device's physics by field name (the specification's "simulated_device", a record's
/// device.simulated_device).
nlohmann::json simulated_device_object(const SimulatedDeviceParameters& parameters);

}  // namespace calligraphy::trial_detail
