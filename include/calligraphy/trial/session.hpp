#pragma once
/// \file session.hpp
/// One guided writing trial, stepped one servo tick at a time from any loop: the renderer (paper
/// sections 4-6) and the recorder of a scene. `step` is the whole servo path of a trial: call it with the
/// state read from the device and write the force it returns. It is what `run_trial` calls, in lock-step
/// and on the `ServoLoop` alike, and what an application with its own servo loop calls:
///
///     TrialSession session(scene, device.info(), options);
///     session.reserve_trace();                              // before a real-time loop
///     DeviceFault fault = DeviceFault::none;
///     DeviceState state;
///     while (running) {                                    // the application's 1 kHz loop
///       if ((fault = device.read_state(state)) != DeviceFault::none) break;
///       const ServoCommand command = session.step(state);
///       if ((fault = device.write_force(command.force_n)) != DeviceFault::none) break;
///       if (command.stop) break;
///     }
///     TrialResult result = fault == DeviceFault::none
///         ? session.finish(TrialEnd::completed)
///         : session.finish(TrialEnd::device_fault, device_fault_message(fault, device.info().model));
///
/// `step` never locks, logs or throws, and after `reserve_trace()` it never allocates; it asks to stop
/// when every stroke is written or `max_duration_s` x `rate_hz` ticks were stepped. With a display
/// channel attached (`attach_display`, or `TrialOptions::display`), `step` also publishes the tick for an
/// application's display thread (display.hpp), still without allocation, lock or wait, and `finish`
/// pushes the trial's end.
#include <cstddef>
#include <optional>
#include <string>

#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

class TrialSession {
 public:
  /// What `servo_callback` wraps: steps the session on a `ServoLoop`.
  struct ServoTick {
    TrialSession* session;
    ServoCommand operator()(const DeviceState& state, double dt_s) const noexcept;
  };

  /// `scene` must outlive the session. The renderer takes the device's limits and its intrinsic damping
  /// (`DeviceInfo::damping_n_s_per_m`, for the stiffness bound) from `device`. Throws InvalidArgument for
  /// bad options or a device whose info is unusable (max force <= 0).
  TrialSession(const Scene& scene, const DeviceInfo& device, const TrialOptions& options);
  /// The same with options already checked (checked.hpp: `run_trial`'s, or an application's
  /// `Checked<TrialOptions>::check`): nothing of them is validated again, down to the renderer.
  TrialSession(const Scene& scene, const DeviceInfo& device, const Checked<TrialOptions>& options);

  /// Allocates (and touches) the trace for `max_duration_s` x `rate_hz` ticks, about 80 bytes a tick,
  /// so that `step` never allocates: for a real-time loop. Nothing when the trace is not kept.
  void reserve_trace();

  /// Publishes every later tick into `channel` (not owned; it must outlive the session), or stops
  /// publishing for nullptr. Allocates: call it before the servo loop starts, not while it runs.
  /// The constructor attaches `options.display`.
  void attach_display(DisplayChannel* channel);

  /// One servo tick: renders the force for `state` and records the tick. `stop` is set when every
  /// stroke is written or the time limit is reached; a step past the time limit (a loop that went on) records
  /// nothing and commands zero force, with `stop` set. Servo path: no lock, log or exception, and no
  /// allocation after `reserve_trace()`. Times: the trial's clock starts at 0 with the first tick;
  /// `state.time_s` is on the device's clock (any origin) and only its differences are used. A stamp that is
  /// not finite gives zero force (a rejected reading); it and a stamp before the previous one are recorded at
  /// the previous tick's time (the recorded clock never runs backwards).
  ServoCommand step(const DeviceState& state) noexcept;

  /// The session as a `ServoLoop`'s callback: `ServoLoop loop(device, session.servo_callback(), options)`.
  /// Each tick is `step`; the callback says the session's rate, so `ServoLoop::start()` refuses a loop or a
  /// device clock at another rate (InvalidArgument naming both), and `finish` then knows that ticks that came
  /// slower than `rate_hz` were late, not misconfigured. For a `ServoLoop` only (passed to it as is, not
  /// through a `ServoCallback`); the session must outlive the loop's run.
  [[nodiscard]] RatedServoCallback<ServoTick> servo_callback() noexcept {
    return {ServoTick{this}, options_.rate_hz, servo_rate_name()};
  }
  /// The rate `step` must be called at [Hz] (`TrialOptions::rate_hz`) and where it was set (for `ticking`).
  [[nodiscard]] double servo_rate_hz() const noexcept { return options_.rate_hz; }
  [[nodiscard]] static const char* servo_rate_name() noexcept { return "TrialOptions::rate_hz"; }

  /// What the renderer made of the last step (state, active stroke, hint, force, events).
  [[nodiscard]] const RenderOutput& last_output() const noexcept { return last_output_; }
  /// Ticks stepped so far.
  [[nodiscard]] std::size_t ticks() const noexcept { return ticks_; }
  /// True once every stroke of the scene is written.
  [[nodiscard]] bool finished() const noexcept { return last_output_.finished; }
  /// True once the ticks reach `max_duration_s` x `rate_hz`.
  [[nodiscard]] bool out_of_time() const noexcept { return ticks_ >= max_ticks_; }
  [[nodiscard]] const TrialOptions& options() const noexcept { return options_; }

  /// Closes the metrics at `end_time_s` (when the trial ended, on the device's clock as the states
  /// stepped; the last tick's time when negative) and returns the recording with how it ended. `reason` is
  /// kept as `abort_reason`. Call once, after the loop stopped stepping; the session is spent after it (a
  /// second call throws StateError). With
  /// a display attached it pushes the `trial_ended` event. When the device's clock says the ticks came more
  /// than 10 % off `rate_hz` (over 100 ticks or more: `TrialResult::device_tick_rate_hz`), logs a warning
  /// with the measured rate: late ticks (load on the machine) when they came slower on a rate-checked loop
  /// (`servo_callback`), else also the possibility that the application's loop steps at another rate.
  [[nodiscard]] TrialResult finish(TrialEnd end, std::string reason = {}, double end_time_s = -1.0);

 private:
  [[nodiscard]] std::string tick_rate_warning(double measured_hz) const;

  TrialOptions options_;
  Renderer renderer_;
  TrialRecorder recorder_;
  RenderOutput last_output_{};
  std::optional<DisplayPublisher> display_;
  std::size_t ticks_ = 0;
  std::size_t max_ticks_ = 0;
  double last_time_s_ = 0.0;      // the trial's clock: 0 at the first tick
  double device_origin_s_ = 0.0;  // the device's time stamp of the first tick
  bool rate_checked_ = false;     // stepped by a ServoLoop that checked the rates at start (servo_callback)
  bool origin_set_ = false;       // device_origin_s_ holds a finite time stamp
  bool spent_ = false;            // finish() was called
};

}  // namespace calligraphy
