#include "calligraphy/trial/realtime_trial.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

const char* to_string(TrialEnd end) noexcept {
  switch (end) {
    case TrialEnd::finished:
      return "finished";
    case TrialEnd::max_duration:
      return "max_duration";
    case TrialEnd::stopped_by_hook:
      return "stopped_by_hook";
    case TrialEnd::fault:
      return "fault";
  }
  return "unknown";
}

void RealtimeTrialOptions::validate() const {
  if (!(max_duration_s > 0.0) || !std::isfinite(max_duration_s)) {
    throw InvalidArgument("RealtimeTrialOptions.max_duration_s = " + std::to_string(max_duration_s) +
                          " must be > 0");
  }
  force.validate();
  loop.validate();
}

RealtimeTrialResult run_realtime_trial(HapticDevice& device, const Scene& scene,
                                       const RealtimeTrialOptions& options) {
  options.validate();
  RendererOptions render_options;
  render_options.rate_hz = options.loop.rate_hz;
  render_options.safety = options.safety;
  render_options.passivity = options.passivity;
  render_options.device_damping_n_s_per_m = options.device_damping_n_s_per_m;
  Renderer renderer(scene, options.force, device.info(), render_options);
  TrialRecorder recorder(scene, options.keep_trace);
  const double period_s = 1.0 / options.loop.rate_hz;
  const auto max_ticks = static_cast<std::size_t>(std::ceil(options.max_duration_s * options.loop.rate_hz));

  recorder.reserve(max_ticks);  // allocated and touched here: the loop never allocates for the trace
  std::size_t count = 0;
  double last_time_s = 0.0;
  TrialEnd end = TrialEnd::max_duration;

  ServoLoop loop(
      device,
      [&](const DeviceState& state, double /*dt_s*/) -> ServoCommand {
        const RenderOutput out = renderer.tick(state);
        recorder.record(state, out);
        ++count;
        last_time_s = state.time_s;
        ServoCommand command{out.force_n, false};
        if (out.finished) {
          end = TrialEnd::finished;
          command.stop = true;
        } else if (options.after_tick && !options.after_tick(state, out, period_s)) {
          end = TrialEnd::stopped_by_hook;
          command.stop = true;
        } else if (count >= max_ticks) {
          end = TrialEnd::max_duration;
          command.stop = true;
        }
        return command;
      },
      options.loop);

  loop.start();
  RealtimeTrialResult result;
  try {
    loop.wait();
  } catch (...) {  // reported in the result; the recording is kept
    end = TrialEnd::fault;
  }
  result.fault = loop.stop();
  if (result.fault) end = TrialEnd::fault;
  result.loop = loop.stats();
  result.end = end;

  recorder.finish(last_time_s);
  result.trial.metrics = recorder.metrics();
  result.trial.trace = recorder.trace();
  return result;
}

RealtimeTrialResult run_realtime_simulated_trial(const Scene& scene, const TrialOptions& trial,
                                                 const ServoLoopOptions& loop) {
  trial.validate();
  SimulatedDevice device(trial.device);
  SimulatedWriter writer(scene, trial.writer, trial.seed);
  device.attach_hand(&writer);
  device.open();

  RealtimeTrialOptions options;
  options.force = trial.force;
  options.safety = trial.safety;
  options.passivity = trial.passivity;
  options.device_damping_n_s_per_m = trial.device.damping_n_s_per_m;
  options.loop = loop;
  options.max_duration_s = trial.max_duration_s;
  options.keep_trace = trial.keep_trace;
  options.after_tick = [&](const DeviceState& state, const RenderOutput& out, double period_s) {
    // As run_simulated_trial: the force is applied before the physics step (the loop writes it again
    // after the callback returns, which for the simulated device changes nothing).
    device.write_force(out.force_n);
    writer.observe(out, state);
    if (writer.done()) return false;
    device.advance(period_s);
    return true;
  };
  RealtimeTrialResult result = run_realtime_trial(device, scene, options);
  device.close();
  return result;
}

}  // namespace calligraphy
