#include <cmath>
#include <string>

#include "calligraphy/errors.hpp"
#include "calligraphy/trial.hpp"

namespace calligraphy {

void TrialOptions::validate() const {
  if (!(rate_hz >= 100.0 && rate_hz <= 100000.0)) {
    throw InvalidArgument("TrialOptions.rate_hz = " + std::to_string(rate_hz) + " must be in [100, 100000] Hz");
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
  SimulatedWriter writer(scene, options.writer, options.seed);
  RendererOptions render_options;
  render_options.rate_hz = options.rate_hz;
  render_options.device_damping_n_s_per_m = options.device.damping_n_s_per_m;
  render_options.safety = options.safety;
  render_options.passivity = options.passivity;
  Renderer renderer(scene, options.force, device.info(), render_options);
  TrialRecorder recorder(scene, options.keep_trace);
  device.attach_hand(&writer);
  device.open();

  const double dt = 1.0 / options.rate_hz;
  const auto ticks = static_cast<std::size_t>(std::ceil(options.max_duration_s * options.rate_hz));
  for (std::size_t k = 0; k < ticks; ++k) {
    const DeviceState state = device.read_state();
    const RenderOutput out = renderer.tick(state);
    device.write_force(out.force_n);
    recorder.record(state, out);
    if (out.finished) break;
    writer.observe(out, state);
    if (writer.done()) break;
    device.advance(dt);
  }
  device.close();
  recorder.finish(device.time());
  return {recorder.metrics(), recorder.trace()};
}

}  // namespace calligraphy
