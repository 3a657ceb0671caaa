#pragma once
/// \file servo_loop.hpp
/// The real-time servo loop: at a fixed rate, reads the device state, calls a callback that returns a force
/// command, and writes the force (the paper runs its haptic loop at 1 kHz, sections 1 and 7). The loop's
/// structure follows libfranka's `Robot::control` callback loop and its `RealtimeConfig` {enforce, ignore}.
///
/// Who keeps the time: a device whose driver owns a servo thread (`HapticDevice::servo_clock()`, e.g.
/// OpenHaptics' scheduler) runs each tick inside the driver's frame, so the force answers the state read in
/// the same frame; the realtime settings are then the driver's (only `lock_memory` applies), and `rate_hz`
/// must equal the driver's rate. Any other device gets a dedicated thread with absolute deadlines. The
/// tick, its guards and its statistics are the same either way.
///
/// Late ticks do not end the loop: a force computed from a state older than `max_force_age_s` is
/// replaced by zero force (a stale force on a stiff virtual fixture is what makes a sampled haptic loop
/// active: Colgate & Schenkel 1997), and after a stall the deadlines are re-anchored to the present
/// instead of being caught up. Only a stall longer than `stall_timeout_s` ends the run, safely.
///
/// Inside the loop nothing allocates, locks, logs synchronously, builds a string or lets an exception
/// escape: a device fault is the `DeviceFault` code `read_state` or `write_force` returns (no exception
/// on that path), a callback's exception is caught on the loop thread; either way the force is zeroed,
/// forces are disabled, the fault is recorded (the code with its fixed message), the loop stops, and
/// `wait()` throws it on the caller's thread (`throw_device_fault` for a device fault, the callback's own
/// exception). Statistics are atomics, readable from any thread while the loop runs. Log records go
/// through a lock-free queue to a normal thread that calls spdlog. Linux only (clock_nanosleep,
/// SCHED_FIFO).
#include <array>
#include <concepts>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// As libfranka's RealtimeConfig: `enforce` makes `start()` throw RealtimeError unless every requested
/// setting (SCHED_FIFO priority, CPU pinning, locked memory) was applied; `ignore` tries the requested
/// settings, runs anyway, and records what was obtained in `ServoLoopStats::realtime`.
enum class RealtimeMode { enforce, ignore };

/// The one spelling of each real-time mode.
template <>
struct EnumTable<RealtimeMode> {
  static constexpr std::string_view name = "RealtimeMode";
  static constexpr std::array<EnumEntry<RealtimeMode>, 2> entries{{
      {RealtimeMode::enforce, "enforce",
       "fail unless SCHED_FIFO, CPU pinning and locked memory are obtained"},
      {RealtimeMode::ignore, "ignore", "run with what the process is given"},
  }};
};

/// The SCHED_FIFO priority a program that exists to run the haptic loop asks for (the command line's trials
/// and study sessions): above the kernel's threaded interrupts (50), below its watchdogs (99).
inline constexpr int kDedicatedServoPriority = 80;

/// The longest stall bound a loop takes (`ServoLoopOptions::stall_timeout_s`) [s]: longer is no watchdog.
inline constexpr double kMaxStallTimeoutS = 60.0;

/// The defaults suit a library inside a larger program: normal scheduling, no CPU pinning and no memory
/// locking, nothing that changes the process. A program that exists to run the loop asks for them
/// (`priority = kDedicatedServoPriority`, `lock_memory = true`; docs/servo-loop.md).
struct ServoLoopOptions {
  double rate_hz = 1000.0;  ///< servo rate [Hz], in [100, 10000]
  RealtimeMode realtime = RealtimeMode::ignore;
  /// SCHED_FIFO priority of the loop thread, 1..99; 0 (the default) asks for none (normal scheduling; not
  /// allowed with `enforce`). Usually needs CAP_SYS_NICE or an rtprio limit.
  int priority = 0;
  int cpu = -1;  ///< pin the loop thread to this CPU; -1: no pinning
  /// mlockall(MCL_CURRENT | MCL_FUTURE) at start, so the loop never takes a page fault. Process-wide
  /// and not undone at stop, so off by default. Unavailable in sanitizer builds (their shadow memory
  /// cannot be locked): there `enforce` throws and `ignore` records it as not obtained.
  bool lock_memory = false;
  /// Stale-force guard [s], in (0, 1]: the longest time from the start of a tick's `read_state` to the
  /// return of its callback for which the callback's force is still written. A later tick (the thread
  /// lost the CPU inside the tick) commands zero force instead, counts it in `forces_withheld`, and the
  /// loop goes on. Default 2 ms, 2 periods at the default 1 kHz (docs/servo-loop.md gives the reasoning).
  double max_force_age_s = 0.002;
  /// Stall bound [s], in [0, 60]; 0 turns it off. A stall is the time the device held one force command
  /// beyond one period (the gap between two successive force updates, less a period). A tick that ends a
  /// stall longer than this ends the run: zero force, forces disabled, a `watchdog` fault with a fixed
  /// message; the tick is counted. Checked when the loop thread runs again: a thread that never resumes
  /// is a case for the device's own command watchdog. Default 50 ms, the Phantom backend's own command
  /// watchdog. (The command line's `--watchdog-ms N` sets this to N / 1000.)
  double stall_timeout_s = 0.050;
  bool enable_forces_on_start = true;  ///< `start()` calls `device.enable_forces(true)`

  /// Throws InvalidArgument naming the field, its value and its range when a value is out of range.
  void validate() const;
  [[nodiscard]] std::int64_t period_ns() const;
};

/// What the callback returns each tick: the force [N] to command, and whether the loop should stop
/// after this tick (the force is still written; at the stop the loop zeroes it and disables forces).
struct ServoCommand {
  Vec3 force_n = Vec3::Zero();
  bool stop = false;
};

/// Called once per tick on the loop thread with the state just read and the measured time since the
/// previous tick [s] (the nominal period on the first tick). Must not allocate, lock or log; may throw
/// (the loop contains it: see the file comment).
using ServoCallback = std::function<ServoCommand(const DeviceState& state, double dt_s)>;

/// A callable the loop accepts as its callback: invoked as an lvalue with (state, dt_s), it returns a
/// ServoCommand (by value or reference).
template <typename Callback>
concept servo_callback_for = std::is_invocable_v<Callback&, const DeviceState&, double> &&
    std::is_same_v<std::decay_t<std::invoke_result_t<Callback&, const DeviceState&, double>>, ServoCommand>;

/// Something built for one servo rate, whose time-based parts (fades, filters, a replay's clock) assume that
/// many ticks a second: `Renderer` and `TrialSession` are. `servo_rate_name()` names where the rate was set
/// (e.g. "RendererOptions::rate_hz"), for the error that refuses a loop at another rate.
template <typename T>
concept BuiltForServoRate = requires(const T& ticked) {
  { ticked.servo_rate_hz() } -> std::convertible_to<double>;
  { ticked.servo_rate_name() } -> std::convertible_to<const char*>;
};

/// A servo callback that says the rate it was built for (what `ticking` returns): handed to a `ServoLoop`,
/// `start()` refuses a loop or a device clock at another rate.
template <typename Callback>
struct RatedServoCallback {
  Callback callback;
  double rate_hz = 0.0;        ///< the rate the callback was built for [Hz]
  const char* rate_name = "";  ///< where that rate was set (a static string; nullptr or "": not said)
  ServoCommand operator()(const DeviceState& state, double dt_s) { return callback(state, dt_s); }
  [[nodiscard]] double servo_rate_hz() const noexcept { return rate_hz; }
  [[nodiscard]] const char* servo_rate_name() const noexcept { return rate_name; }
};

/// `callback` as the servo callback of `ticked` (a `Renderer`, a `TrialSession`), carrying its rate to the
/// loop: `ServoLoop loop(device, ticking(renderer, [&](const DeviceState& s, double) {...}), options)`.
/// `start()` then throws InvalidArgument, naming both rates, when `ServoLoopOptions::rate_hz` or the device's
/// own servo clock runs at another rate. Only the rate is read from `ticked`, now.
template <BuiltForServoRate Ticked, typename Callback>
[[nodiscard]] RatedServoCallback<std::decay_t<Callback>> ticking(const Ticked& ticked, Callback&& callback) {
  return {std::forward<Callback>(callback), static_cast<double>(ticked.servo_rate_hz()),
          ticked.servo_rate_name()};
}

/// What ended a run. A device's faults are not kinds of their own: they are `device` with the device's
/// `DeviceFault` code in `LoopFault::device` (one taxonomy, device_fault.hpp).
enum class LoopFaultKind {
  none,
  watchdog,  ///< a stall longer than `stall_timeout_s` (the loop's own bound)
  device,    ///< `read_state` or `write_force` returned a fault: `LoopFault::device` says which
  callback,  ///< an exception from the callback or the after-write hook
};
[[nodiscard]] const char* to_string(LoopFaultKind kind) noexcept;

/// The message of a `watchdog` fault (fixed: the loop builds no string; the numbers are in the statistics).
inline constexpr const char* kStallFaultMessage =
    "the servo loop stalled longer than stall_timeout_s; zero force commanded and forces disabled";

struct LoopFault {
  LoopFaultKind kind = LoopFaultKind::none;
  /// The device's fault code for `LoopFaultKind::device` (`link_lost`, `watchdog`, ...); none otherwise.
  DeviceFault device = DeviceFault::none;
  /// `to_string(device)` for a device fault, the exception's what() (truncated to 127 bytes) for a
  /// callback, `kStallFaultMessage` for the watchdog.
  std::string message;
  [[nodiscard]] explicit operator bool() const noexcept { return kind != LoopFaultKind::none; }
};

/// What the realtime settings gave (see `RealtimeMode`).
struct RealtimeStatus {
  /// The ticks ran in the device driver's own servo thread (`HapticDevice::servo_clock()`): its priority
  /// and CPU are the driver's, and the fields below about the loop thread stay unset.
  bool device_clock = false;
  bool fifo_scheduling = false;  ///< the loop thread runs SCHED_FIFO
  int priority = 0;              ///< its priority (0 when not SCHED_FIFO)
  int cpu = -1;                  ///< the CPU it is pinned to, -1 when not pinned
  bool memory_locked = false;    ///< mlockall succeeded
  std::string problems;          ///< what was requested and not obtained, with the system's reason
};

/// One histogram bin of a snapshot: ticks whose value was below `upper_us` (and above the previous bin).
struct HistogramBin {
  double upper_us = 0.0;
  std::uint64_t count = 0;
};

/// A snapshot of the loop's statistics. The counters are read one by one (relaxed atomics), so a
/// snapshot taken while the loop runs may be off by a tick between fields. Percentiles come from
/// fixed-bin histograms and are the upper edge of the bin (1 us bins up to 1 ms for period jitter,
/// 0.1 us bins up to 100 us for callback time, 100x coarser beyond), capped at the exact maximum.
struct ServoLoopStats {
  bool running = false;
  double rate_hz = 0.0;
  std::uint64_t ticks = 0;  ///< callbacks completed (the tick that tripped the stall bound included)
  /// Ticks whose force update (the callback's force, or the zero force that replaced it) reached the
  /// device after the next tick's start time; the tick that tripped the stall bound included.
  std::uint64_t late_ticks = 0;
  std::uint64_t missed_deadlines = 0;  ///< the same count as `late_ticks`, under its earlier name
  std::uint64_t forces_withheld = 0;   ///< ticks that commanded zero force instead of a stale force
  /// The longest time the device held one force command beyond one period [s] (see `stall_timeout_s`).
  double longest_stall_s = 0.0;
  /// Times the deadline grid was re-anchored to the present after a tick ended past the next deadline
  /// (instead of running the missed ticks back to back).
  std::uint64_t deadline_reanchors = 0;
  std::uint64_t skipped_periods = 0;  ///< deadlines that passed without a tick
  /// Period jitter: |time between successive wake-ups - period| [us].
  double period_jitter_us_p50 = 0.0;
  double period_jitter_us_p99 = 0.0;
  double period_jitter_us_max = 0.0;
  double wake_latency_us_max = 0.0;  ///< latest wake-up after an absolute deadline [us]
  /// Callback time: the callback alone, from its call to its return [us].
  double callback_us_mean = 0.0;
  double callback_us_p99 = 0.0;
  double callback_us_max = 0.0;
  std::vector<HistogramBin> period_jitter_histogram;  ///< non-empty bins only
  RealtimeStatus realtime;
  LoopFault fault;  ///< the fault that stopped the last run, if any
};

/// Runs a callback at a fixed rate against a device, on a dedicated thread or on the device driver's own
/// servo thread (see the file comment). Not copyable or movable. The device is used only by the ticking
/// thread between `start()` and the end of the run: do not touch it from other threads meanwhile (the
/// thread's start and join, or the clock's attach and detach, order the accesses).
class ServoLoop {
 public:
  /// Optional, given at construction: called on the loop thread right after each tick's force write (the
  /// callback's force or the zero force that replaced it), except after a tick that asked to stop or ended
  /// the run. A simulation steps its world here, so the force acts during the step; its time counts towards
  /// the stall bound. Same rules as the callback; its exceptions are contained like the callback's.
  using AfterForceWrite = std::function<void()>;

  /// `device` must outlive the loop. Throws InvalidArgument for bad options or an empty callback.
  ServoLoop(HapticDevice& device, ServoCallback callback, const ServoLoopOptions& options = {},
            AfterForceWrite after_write = {});
  /// The same from any callable (a lambda) callable as `ServoCommand(const DeviceState&, double dt_s)`. A
  /// callable that says the rate it was built for (`BuiltForServoRate`: what `ticking` and
  /// `TrialSession::servo_callback` return) has it checked by `start()`.
  template <typename Callback>
  requires(!std::is_same_v<std::decay_t<Callback>, ServoCallback> && servo_callback_for<Callback>)
      ServoLoop(HapticDevice& device, Callback&& callback, const ServoLoopOptions& options = {},
                AfterForceWrite after_write = {})
      : ServoLoop(device, prepare(std::forward<Callback>(callback)), options, std::move(after_write)) {}
  /// Any other callable is refused at compile time with one message saying what is wrong (e.g. one that
  /// returns a bare force, a Vec3). The constraint keeps such a callable away from std::function, whose
  /// own errors would otherwise follow the message by some fifty lines.
  template <typename Callback>
  requires(!std::is_same_v<std::decay_t<Callback>, ServoCallback> && !servo_callback_for<Callback>)
      ServoLoop(HapticDevice& device, Callback&& /*callback*/, const ServoLoopOptions& options = {})
      : ServoLoop(device, ServoCallback{}, options) {
    if constexpr (!std::is_invocable_v<Callback&, const DeviceState&, double>) {
      static_assert(
          kRefused<Callback>,
          "ServoLoop: the callback must be callable as ServoCommand(const DeviceState&, double dt_s)");
    } else if constexpr (std::is_convertible_v<std::invoke_result_t<Callback&, const DeviceState&, double>,
                                               Vec3>) {
      static_assert(kRefused<Callback>,
                    "ServoLoop: the callback returns a Vec3; return ServoCommand{force_n, stop} instead");
    } else {
      static_assert(kRefused<Callback>,
                    "ServoLoop: the callback must return ServoCommand (the force [N] and whether to stop)");
    }
  }
  /// Stops the loop (see `stop()`). Never throws.
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  /// Starts the run: clears the statistics, locks memory when asked, enables forces when asked, then
  /// either attaches to the device's own servo clock or starts the loop thread, applies the realtime
  /// settings on it and returns once they are applied. Throws RealtimeError (mode `enforce`, with the
  /// reason), DeviceError (the device is not open, or from `enable_forces` or the clock's attach),
  /// InvalidArgument (`rate_hz`, or the rate the callback was built for, differs from the device clock's rate
  /// or from each other: both named), Error when its thread or the log's cannot be started (RLIMIT_NPROC, no
  /// memory for a stack: not running then, forces disabled), or StateError when the loop is already running.
  /// A loop that ended (stopped by its callback, by `stop()` or by a fault) can be started again.
  void start();
  /// Asks the loop to stop, waits for the thread to end (or for the device clock's next frame, then
  /// detaches from it; a clock that stopped calling is detached after 100 ms) and returns the fault that
  /// ended the run, if any (none when it was stopped or ended by its callback). Forces are zero and disabled
  /// on return. Never throws; does nothing when not started. Any thread, also several at once and while
  /// another waits in `wait()` (which then returns as for a run stopped). Called from the callback it only
  /// requests the stop (the callback should return `ServoCommand::stop` instead).
  LoopFault stop() noexcept;
  /// Waits until the loop ends by itself (its callback asked to stop, or a fault) and joins it; then
  /// throws the fault: for a device fault `throw_device_fault(code, device.info().model)`
  /// (CommunicationError or SafetyFault), the callback's own exception, or a SafetyFault for a stall
  /// (`kStallFaultMessage`). Returns normally when the run ended without a fault. Blocks forever if
  /// nothing ends it (on a device clock: a driver that stopped calling ends the run as a stall once the
  /// silence passes `stall_timeout_s`, unless the bound is off).
  void wait();
  /// True from `start()` until the loop thread has left its loop (on a device clock: until the frame that
  /// ended the run, or until the driver has been silent longer than `stall_timeout_s`). Any thread.
  [[nodiscard]] bool running() const noexcept;
  /// A snapshot of the statistics; lock-free, from any thread while the loop runs or after it ended (not
  /// concurrently with `start()`, which resets them).
  [[nodiscard]] ServoLoopStats stats() const;
  [[nodiscard]] const ServoLoopOptions& options() const noexcept;

 private:
  // The callback and the rate it was built for (0: it does not say).
  struct Prepared {
    ServoCallback callback;
    double rate_hz = 0.0;
    const char* rate_name = "";
  };
  ServoLoop(HapticDevice& device, Prepared prepared, const ServoLoopOptions& options,
            AfterForceWrite after_write);

  template <typename Callback>
  static Prepared prepare(Callback&& callback) {
    Prepared prepared;
    if constexpr (BuiltForServoRate<std::decay_t<Callback>>) {
      prepared.rate_hz = static_cast<double>(callback.servo_rate_hz());  // read before the callback moves
      prepared.rate_name = callback.servo_rate_name();
    }
    prepared.callback = ServoCallback(std::forward<Callback>(callback));
    return prepared;
  }

  template <typename Callback>
  static constexpr bool kRefused = false;  // false, but only once instantiated for a refused callable

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace calligraphy
