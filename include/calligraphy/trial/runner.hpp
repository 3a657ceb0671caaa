#pragma once
/// \file runner.hpp
/// Runs a whole guided writing trial on any `HapticDevice`, through the code path a real device uses:
/// `open()` (when not open), `calibrate()` (when `!is_calibrated()`), forces on, then once per servo
/// tick `read_state()` -> `TrialSession::step` -> `write_force()`, and at every end forces off and
/// `close()` (a scope guard: also when something throws).
///
/// Pacing (`TrialPacing`): a trial given a hand (hand.hpp: a simulated writer on a device it can move,
/// made by calligraphy/sim) runs lock-step by default: after each tick the hand sees the output and the
/// device advances by 1 / rate_hz of its own time; no wall clock, deterministic for a seed. A trial
/// without a hand is moved by a person and runs in real time on the `ServoLoop` (servo_loop.hpp: its own
/// thread, absolute deadlines, stale-force and stall bounds); a hand runs there too with
/// `TrialPacing::real_time` (it then steps on the loop thread right after each force write).
///
/// Endings: see `TrialEnd`. A device fault (a `DeviceFault` code from `read_state` or `write_force`, a
/// stall of the loop) ends the trial with `aborted` set, the code in `TrialResult::device_fault` and its
/// message (`device_fault_message`) in `abort_reason`; every tick recorded before it is kept. Any
/// exception (from `open()`, `calibrate()`, a hand) turns forces off, closes the device, and propagates.
#include "calligraphy/core/checked.hpp"
#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/hand.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

/// Runs one trial of `scene` on `device` (opened here if it is not open yet, closed at the end), moved by
/// `hand` when one is given (not owned; it must move this device), else by a person. Throws
/// InvalidArgument for bad options, lock-step pacing without a hand, or a device whose info is unusable
/// (the device is closed again), and what `open()`, `calibrate()` or enabling forces throw
/// (DeviceNotFound, CommunicationError, CalibrationNeeded, RealtimeError): no tick was recorded then, and
/// the device is closed.
TrialResult run_trial(HapticDevice& device, const Scene& scene, const TrialOptions& options,
                      TrialHand* hand = nullptr);
/// The same with options already checked (checked.hpp): the one check was the caller's, and nothing of
/// them is validated again down to the renderer. What `run_whole_trial` calls.
TrialResult run_trial(HapticDevice& device, const Scene& scene, const Checked<TrialOptions>& options,
                      TrialHand* hand = nullptr);

}  // namespace calligraphy
