#pragma once
/// \file runner.hpp
/// Runs a whole guided writing trial on any `HapticDevice`, through the code path a real device uses:
/// `open()` (when not open), `calibrate()` (when `!is_calibrated()`), forces on, then once per servo
/// tick `read_state()` -> `TrialSession::step` -> `write_force()`, and at every end forces off and
/// `close()` (a scope guard: also when something throws).
///
/// Pacing (`TrialPacing`): a device with a `HandPort` (hand_port.hpp: the simulated device, the emulated
/// Phantom) is moved by a `SimulatedWriter` and by default runs lock-step: after each tick the writer
/// sees the display and the device advances by 1 / rate_hz of its own time; no wall clock, deterministic
/// for a seed. Any other device (a Phantom, OpenHaptics) is moved by a person and runs in real time on
/// the `ServoLoop` (servo_loop.hpp: its own thread, absolute deadlines, stale-force and stall bounds); a
/// hand-port device runs there too with `TrialPacing::real_time` (its writer and physics then step on the
/// loop thread right after each force write).
///
/// Endings: see `TrialEnd`. A device fault (a `DeviceFault` code from `read_state` or `write_force`, a
/// stall of the loop) ends the trial with `aborted` set, the code in `TrialResult::device_fault` and its
/// message (`device_fault_message`) in `abort_reason`; every tick recorded before it is kept. Any
/// exception (from `open()`, `calibrate()`, a simulated writer) turns forces off, closes the device, and
/// propagates.
#include <string_view>

#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

/// Runs one trial of `scene` on `device` (opened here if it is not open yet, closed at the end).
/// Throws InvalidArgument for bad options or a device whose info is unusable (the device is closed
/// again), and what `open()`, `calibrate()` or enabling forces throw (DeviceNotFound,
/// CommunicationError, CalibrationNeeded, RealtimeError): no tick was recorded then, and the device is
/// closed.
TrialResult run_trial(HapticDevice& device, const Scene& scene, const TrialOptions& options);

/// The trial on the device called `device_name` in `device_registry_with_simulation()` (e.g.
/// "simulated"), created for this trial. Throws DeviceNotFound naming the devices that exist when
/// there is none of that name, and what the other `run_trial` throws.
TrialResult run_trial(std::string_view device_name, const Scene& scene, const TrialOptions& options);

/// The trial on a `SimulatedDevice` made from `options.simulation.device`: lock-step by default, or in
/// real time with `TrialPacing::real_time` (the same trial, paced by the wall clock).
TrialResult run_simulated_trial(const Scene& scene, const TrialOptions& options);

}  // namespace calligraphy
