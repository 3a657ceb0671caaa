#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/trial/device_trial.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy {

void TrialOptions::validate() const {
  if (!(rate_hz >= 100.0 && rate_hz <= 100000.0)) {
    throw InvalidArgument("TrialOptions.rate_hz = " + std::to_string(rate_hz) +
                          " must be in [100, 100000] Hz");
  }
  if (!(max_duration_s > 0.0) || !std::isfinite(max_duration_s)) {
    throw InvalidArgument("TrialOptions.max_duration_s = " + std::to_string(max_duration_s) + " must be > 0");
  }
  force.validate();
  writer.validate();
  device.validate();
}

TrialResult run_simulated_trial(const Scene& scene, const TrialOptions& options) {
  options.validate();
  SimulatedDevice device(options.device);
  DeviceTrialOptions device_options;
  device_options.force = options.force;
  device_options.writer = options.writer;
  device_options.rate_hz = options.rate_hz;
  device_options.seed = options.seed;
  device_options.max_duration_s = options.max_duration_s;
  device_options.keep_trace = options.keep_trace;
  device_options.safety = options.safety;
  device_options.passivity = options.passivity;
  device_options.device_damping_n_s_per_m = options.device.damping_n_s_per_m;
  return run_device_trial(device, scene, device_options);
}

}  // namespace calligraphy
