#pragma once
/// \file realtime_trial.hpp
/// A guided writing trial in real time: the `Renderer` and a trial recorder run inside the `ServoLoop`
/// callback at the loop's rate against any `HapticDevice`: the real-time counterpart of the lock-step
/// `run_simulated_trial`, for a device that moves on its own clock.
///
/// The loop never allocates for the trace: the recorder's trace is reserved (and touched) up front for
/// max_duration_s x rate_hz ticks (`TrialRecorder::reserve`; memory: about 80 bytes per tick, 24 MB for
/// 300 s at 1 kHz), and the trial ends when it is full.
#include <functional>

#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy {

/// Options of a real-time trial.
struct RealtimeTrialOptions {
  ForceLawParameters force{};       ///< `force.guidance` switches guidance on or off
  SafetyChainParameters safety{};   ///< the renderer's safety chain (renderer.hpp)
  PassivityParameters passivity{};  ///< the renderer's passivity controller (off by default)
  /// Physical damping of the device [N s/m] for the renderer's stiffness bound; 0 = unknown.
  double device_damping_n_s_per_m = 0.0;
  ServoLoopOptions loop{};        ///< rate, realtime mode, watchdog
  double max_duration_s = 300.0;  ///< the trial ends after max_duration_s x rate_hz ticks [s]
  bool keep_trace = true;
  /// Optional: called on the loop thread after each tick's force is computed and recorded, with the
  /// state read, what the renderer made of it and the nominal period [s]; returns false to end the trial.
  /// A simulation steps its world here (see `run_realtime_simulated_trial`). Same rules as the callback.
  std::function<bool(const DeviceState&, const RenderOutput&, double period_s)> after_tick;
  /// Throws InvalidArgument when a value is out of range.
  void validate() const;
};

/// Why a real-time trial ended.
enum class TrialEnd { finished, max_duration, stopped_by_hook, fault };
[[nodiscard]] const char* to_string(TrialEnd end) noexcept;

/// A real-time trial's outcome: the recording (kept also when a fault ended the trial), why it ended,
/// the fault if any, and the loop's statistics.
struct RealtimeTrialResult {
  TrialResult trial;
  TrialEnd end = TrialEnd::finished;
  LoopFault fault;
  ServoLoopStats loop;
};

/// Runs a whole trial on `device` (open; forces are enabled at the start and disabled at the end) in a
/// `ServoLoop`. Each tick: read the state, `Renderer::tick`, record, `after_tick`, write the force. Ends
/// when every stroke is written, after max_duration_s, when `after_tick` returns false, or on a device or
/// watchdog fault (reported in the result, not thrown). Blocks until the end. Throws InvalidArgument for
/// bad options, RealtimeError / DeviceError from `ServoLoop::start`.
RealtimeTrialResult run_realtime_trial(HapticDevice& device, const Scene& scene,
                                       const RealtimeTrialOptions& options);

/// The real-time counterpart of `run_simulated_trial`: a `SimulatedDevice` held by a `SimulatedWriter`,
/// stepped inside the loop by the nominal period after each tick (lock-step physics, paced by the wall
/// clock). With the same options and seed it records the same trial as `run_simulated_trial`, ticks
/// skipped by a late loop aside (they delay the trial but do not change it). Uses `trial.force`,
/// `trial.writer`, `trial.device`, `trial.seed`, `trial.max_duration_s`, `trial.keep_trace` and takes the
/// rate from `loop.rate_hz`. The simulated writer allocates when it plans a stroke: it stands in for the
/// human, not for the servo path. Throws InvalidArgument for bad options.
RealtimeTrialResult run_realtime_simulated_trial(const Scene& scene, const TrialOptions& trial,
                                                 const ServoLoopOptions& loop);

}  // namespace calligraphy
