// The trial loop shared by every device (device_trial.hpp).
#include "calligraphy/trial/device_trial.hpp"

#include <cmath>
#include <optional>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/sim/hand_port.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "calligraphy/trial/realtime_trial.hpp"

namespace calligraphy {
namespace {

// Forces off and link closed after a fault or at the end; never throws (the link may be gone).
void stop_device(HapticDevice& device) noexcept {
  try {
    device.enable_forces(false);
  } catch (...) {
    // Disabling is documented not to throw; a broken backend must still get close().
  }
  device.close();
}

}  // namespace

void DeviceTrialOptions::validate() const {
  if (!(rate_hz >= 100.0 && rate_hz <= 100000.0)) {
    throw InvalidArgument("DeviceTrialOptions.rate_hz = " + std::to_string(rate_hz) +
                          " must be in [100, 100000] Hz");
  }
  if (!(max_duration_s > 0.0) || !std::isfinite(max_duration_s)) {
    throw InvalidArgument("DeviceTrialOptions.max_duration_s = " + std::to_string(max_duration_s) +
                          " must be > 0");
  }
  force.validate();
  writer.validate();
  if (pacing == TrialPacing::real_time && rate_hz > 10000.0) {
    throw InvalidArgument("DeviceTrialOptions.rate_hz = " + std::to_string(rate_hz) +
                          " must be at most 10000 Hz in real time (the ServoLoop's range)");
  }
}

namespace {

RendererOptions renderer_options(const DeviceTrialOptions& options) {
  RendererOptions render;
  render.rate_hz = options.rate_hz;
  render.safety = options.safety;
  render.passivity = options.passivity;
  render.device_damping_n_s_per_m = options.device_damping_n_s_per_m;
  return render;
}

// Real-time pacing on the ServoLoop (the device is open and calibrated; the loop enables and disables
// forces). A hand-port device's writer and physics step inside the loop after each tick.
TrialResult run_on_servo_loop(HapticDevice& device, const Scene& scene, const DeviceTrialOptions& options,
                              HandPort* hand_port, SimulatedWriter* writer) {
  RealtimeTrialOptions realtime;
  realtime.force = options.force;
  realtime.safety = options.safety;
  realtime.passivity = options.passivity;
  realtime.device_damping_n_s_per_m = options.device_damping_n_s_per_m;
  realtime.loop = options.loop;
  realtime.loop.rate_hz = options.rate_hz;
  realtime.max_duration_s = options.max_duration_s;
  realtime.keep_trace = options.keep_trace;
  if (hand_port != nullptr) {
    realtime.after_tick = [&](const DeviceState& state, const RenderOutput& out, double period_s) {
      device.write_force(out.force_n);  // as lock-step: the force acts during the physics step
      writer->observe(out, state);
      if (writer->done()) return false;
      hand_port->advance(period_s);
      return true;
    };
  }
  RealtimeTrialResult outcome = run_realtime_trial(device, scene, realtime);
  TrialResult result = std::move(outcome.trial);
  if (outcome.fault) {
    result.aborted = true;
    result.abort_reason = outcome.fault.message;  // the device's message, or the watchdog's reason
  }
  return result;
}

}  // namespace

TrialResult run_device_trial(HapticDevice& device, const Scene& scene, const DeviceTrialOptions& options) {
  options.validate();
  // Discovered once: the loop below never asks again.
  HandPort* const hand_port = dynamic_cast<HandPort*>(&device);
  std::optional<SimulatedWriter> writer;
  if (hand_port != nullptr) {
    writer.emplace(scene, options.writer, options.seed);
    hand_port->attach_hand(&*writer);
  }

  if (hand_port == nullptr && options.pacing == TrialPacing::lock_step) {
    throw InvalidArgument("lock-step pacing needs a device a simulated writer can move (a HandPort); '" +
                          device.info().model + "' is moved by a person: use real-time pacing");
  }
  const bool real_time = hand_port == nullptr || options.pacing == TrialPacing::real_time;

  std::optional<Renderer> renderer;
  try {
    if (!device.is_open()) device.open();
    if (!device.is_calibrated()) device.calibrate();
    // After open(): some devices know their limits only then (OpenHaptics reads them from the driver).
    if (real_time) {
      TrialResult result = run_on_servo_loop(device, scene, options, hand_port, writer ? &*writer : nullptr);
      if (hand_port != nullptr) hand_port->attach_hand(nullptr);
      stop_device(device);
      return result;
    }
    renderer.emplace(scene, options.force, device.info(), renderer_options(options));
    device.enable_forces(true);
  } catch (...) {
    if (hand_port != nullptr) hand_port->attach_hand(nullptr);
    stop_device(device);
    throw;
  }

  // Lock-step from here on (the real-time branch returned above).
  TrialRecorder recorder(scene, options.keep_trace);
  const double dt = 1.0 / options.rate_hz;
  const auto ticks = static_cast<std::size_t>(std::ceil(options.max_duration_s * options.rate_hz));
  TrialResult result;
  double end_time = 0.0;
  try {
    for (std::size_t k = 0; k < ticks; ++k) {
      const DeviceState state = device.read_state();
      const RenderOutput out = renderer->tick(state);
      device.write_force(out.force_n);
      recorder.record(state, out);
      end_time = state.time_s;
      if (out.finished) break;
      writer->observe(out, state);
      if (writer->done()) break;
      hand_port->advance(dt);
      // The time budget ran out after this tick: the trial lasted until the next tick would start.
      if (k + 1 == ticks) end_time = state.time_s + dt;
    }
  } catch (const DeviceError& e) {
    // CommunicationError (link lost), SafetyFault, or another device fault of an application's device.
    result.aborted = true;
    result.abort_reason = e.what();
  } catch (...) {
    // Not a device fault (a bug, std::bad_alloc): forces off before it propagates.
    if (hand_port != nullptr) hand_port->attach_hand(nullptr);
    stop_device(device);
    throw;
  }
  if (hand_port != nullptr) hand_port->attach_hand(nullptr);
  stop_device(device);
  recorder.finish(end_time);
  result.metrics = recorder.metrics();
  result.trace = recorder.trace();
  return result;
}

TrialResult run_device_trial(std::string_view device_name, const Scene& scene,
                             const DeviceTrialOptions& options) {
  options.validate();  // before a device is created (and possibly opened by its backend)
  const std::unique_ptr<HapticDevice> device = device_registry_with_simulation().create(device_name);
  return run_device_trial(*device, scene, options);
}

}  // namespace calligraphy
