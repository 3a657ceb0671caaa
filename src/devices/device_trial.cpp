// The trial loop shared by every device (device_trial.hpp).
#include "calligraphy/device_trial.hpp"

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <thread>

#include "calligraphy/device_registry.hpp"
#include "calligraphy/errors.hpp"
#include "calligraphy/hand_port.hpp"
#include "calligraphy/simulated_writer.hpp"

namespace calligraphy {
namespace {

// Wall-clock pacing for devices moved by a person: tick k starts at start + k * period. Absolute
// deadlines keep a late tick from delaying every later one. One small function so that a real-time
// servo loop can replace it.
class WallClockPacer {
 public:
  explicit WallClockPacer(double rate_hz)
      : period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(1.0 / rate_hz))),
        start_(std::chrono::steady_clock::now()) {}
  void wait_for_tick(std::size_t tick) const {
    std::this_thread::sleep_until(start_ + static_cast<std::chrono::steady_clock::rep>(tick) * period_);
  }

 private:
  std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point start_;
};

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
}

TrialResult run_device_trial(HapticDevice& device, const Scene& scene, const DeviceTrialOptions& options) {
  options.validate();
  TrialRecorder recorder(scene, options.keep_trace);
  const double dt = 1.0 / options.rate_hz;
  const auto ticks = static_cast<std::size_t>(std::ceil(options.max_duration_s * options.rate_hz));

  // Discovered once: the loop below never asks again.
  HandPort* const hand_port = dynamic_cast<HandPort*>(&device);
  std::optional<SimulatedWriter> writer;
  if (hand_port != nullptr) {
    writer.emplace(scene, options.writer, options.seed);
    hand_port->attach_hand(&*writer);
  }

  std::optional<Renderer> renderer;
  try {
    if (!device.is_open()) device.open();
    if (!device.is_calibrated()) device.calibrate();
    // After open(): some devices know their limits only then (OpenHaptics reads them from the driver).
    renderer.emplace(scene, options.force, device.info());
    device.enable_forces(true);
  } catch (...) {
    if (hand_port != nullptr) hand_port->attach_hand(nullptr);
    stop_device(device);
    throw;
  }

  TrialResult result;
  double end_time = 0.0;
  std::optional<WallClockPacer> pacer;
  if (hand_port == nullptr) pacer.emplace(options.rate_hz);
  try {
    for (std::size_t k = 0; k < ticks; ++k) {
      if (pacer) pacer->wait_for_tick(k);
      const DeviceState state = device.read_state();
      const RenderOutput out = renderer->tick(state);
      device.write_force(out.force_n);
      recorder.record(state, out);
      end_time = state.time_s;
      if (out.finished) break;
      if (writer) {
        writer->observe(out, state);
        if (writer->done()) break;
        hand_port->advance(dt);
      }
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
  const std::unique_ptr<HapticDevice> device = device_registry().create(device_name);
  return run_device_trial(*device, scene, options);
}

}  // namespace calligraphy
