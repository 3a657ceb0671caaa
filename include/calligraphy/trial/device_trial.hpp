#pragma once
/// \file device_trial.hpp
/// A guided writing trial on any `HapticDevice`, through the code path a real device uses:
/// `open()`, `calibrate()` when `!is_calibrated()`, `enable_forces(true)`, then once per servo tick
/// `read_state()` -> `Renderer::tick` -> `write_force()` -> `TrialRecorder::record`, and
/// `enable_forces(false)`, `close()` at the end.
///
/// Pacing (`TrialPacing`): a device with a `HandPort` (hand_port.hpp; the simulated device, the emulated
/// Phantom) is moved by a `SimulatedWriter` and by default runs lock-step: after each tick the writer
/// sees the display and the device advances by 1 / rate_hz of its own time, no wall clock, deterministic
/// for a seed. Any other device (a real Phantom, OpenHaptics) is moved by a person and runs in real time
/// on the `ServoLoop` (servo_loop.hpp: its own thread, absolute deadlines, watchdog); a hand-port device
/// runs there too when `pacing` is `real_time` (the writer and the device's physics then step inside the
/// loop, after each tick). In real time, a fault of the loop (device error, watchdog) aborts the trial
/// like a device fault below.
///
/// Faults: a `CommunicationError`, `SafetyFault` (or any other `DeviceError`) from `read_state` or
/// `write_force` ends the trial; forces are disabled (best effort), the device is closed, and the result
/// keeps every tick recorded before the fault, with `aborted` set and `abort_reason` the device's
/// message. Any other exception also turns forces off and closes the device, then propagates.
#include <cstdint>
#include <string_view>

#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy {

/// How a trial's ticks are paced (see the file comment).
enum class TrialPacing {
  automatic,  ///< lock-step for a device with a hand port, real time on the ServoLoop for any other
  lock_step,  ///< no wall clock; only for a device with a hand port (else InvalidArgument)
  real_time,  ///< the ServoLoop at `rate_hz`, with `loop`'s realtime settings and watchdog
};

/// Options of a trial on a device. The device's own parameters are the device's business.
struct DeviceTrialOptions {
  ForceLawParameters force{};                      ///< `force.guidance` switches guidance on or off
  WriterProfile writer = WriterProfile::novice();  ///< the simulated writer (hand-port devices only)
  double rate_hz = 1000.0;                         ///< servo rate [Hz]
  std::uint64_t seed = 0;                          ///< seeds the simulated writer
  double max_duration_s = 300.0;                   ///< stop after this much device time [s]
  bool keep_trace = true;
  SafetyChainParameters safety{};   ///< the renderer's safety chain (renderer.hpp)
  PassivityParameters passivity{};  ///< the renderer's passivity controller (off by default)
  /// Physical damping of the device [N s/m] for the renderer's stiffness bound; 0 = unknown.
  double device_damping_n_s_per_m = 0.0;
  TrialPacing pacing = TrialPacing::automatic;
  /// Real-time pacing only: realtime mode, priority, CPU, watchdog. Its rate is replaced by `rate_hz`.
  ServoLoopOptions loop{};
  /// Throws InvalidArgument when the rate is not in [100, 100000] Hz (lock-step) or [100, 10000] Hz
  /// (real time), the duration is not positive, or the force law or writer is out of range.
  void validate() const;
};

/// Runs one trial of `scene` on `device` (opened here if it is not open yet, closed at the end).
/// Returns the metrics and, when `keep_trace`, the trace; `aborted` when the device failed mid-trial.
/// The renderer takes the device's limits from `info()` after `open()`. Throws InvalidArgument for bad
/// options or a device whose info is unusable (max force <= 0; the device is closed again), and
/// what `open()`, `calibrate()` or `enable_forces(true)` throw (DeviceNotFound, CommunicationError,
/// CalibrationNeeded): no tick was recorded then, and the device is closed.
TrialResult run_device_trial(HapticDevice& device, const Scene& scene, const DeviceTrialOptions& options);

/// The trial on the device called `device_name` in `device_registry()` (e.g. "simulated",
/// "emulated-phantom"), created for this trial: what `calligraphy trial --device NAME` runs. Throws
/// DeviceNotFound naming the devices that exist when there is none of that name, and what
/// `run_device_trial` throws.
TrialResult run_device_trial(std::string_view device_name, const Scene& scene,
                             const DeviceTrialOptions& options);

}  // namespace calligraphy
