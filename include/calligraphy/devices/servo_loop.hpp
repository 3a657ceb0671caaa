#pragma once
/// \file servo_loop.hpp
/// The real-time servo loop: a dedicated thread that, at a fixed rate with absolute deadlines,
/// reads the device state, calls a callback that returns a force command, and writes the force
/// (the paper runs its haptic loop at 1 kHz, sections 1 and 7). The loop's structure follows libfranka's
/// `Robot::control` callback loop and its `RealtimeConfig` {enforce, ignore} (Franka Robotics' C++ client).
///
/// Inside the loop nothing allocates, locks, logs synchronously or lets an exception escape: device
/// faults and callback exceptions are caught on the loop thread, the force is zeroed, forces are
/// disabled, the fault is recorded, the loop stops, and `wait()` rethrows it on the caller's thread.
/// Statistics are atomics, readable from any thread while the loop runs. Log records go through a
/// lock-free queue to a normal thread that calls spdlog. Linux only (clock_nanosleep, SCHED_FIFO).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// The realtime settings were required (`RealtimeMode::enforce`) and could not be applied; the message
/// names the setting and the system's reason (e.g. "SCHED_FIFO priority 80: Operation not permitted
/// (EPERM)"). Thrown by `ServoLoop::start`.
class RealtimeError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// As libfranka's RealtimeConfig: `enforce` makes `start()` throw RealtimeError unless every requested
/// setting (SCHED_FIFO priority, CPU pinning, locked memory) was applied; `ignore` tries the requested
/// settings, runs anyway, and records what was obtained in `ServoLoopStats::realtime`.
enum class RealtimeMode { enforce, ignore };

struct ServoLoopOptions {
  double rate_hz = 1000.0;  ///< servo rate [Hz], in [100, 10000]
  RealtimeMode realtime = RealtimeMode::ignore;
  /// SCHED_FIFO priority of the loop thread, 1..99; 0 asks for none (normal scheduling; not allowed
  /// with `enforce`).
  int priority = 80;
  int cpu = -1;  ///< pin the loop thread to this CPU; -1: no pinning
  /// mlockall(MCL_CURRENT | MCL_FUTURE) at start, so the loop never takes a page fault. Process-wide
  /// and not undone at stop. Unavailable in sanitizer builds (their shadow memory cannot be locked):
  /// there `enforce` throws and `ignore` records it as not obtained.
  bool lock_memory = true;
  /// Watchdog: a tick whose force would be written more than this many periods after its deadline is
  /// not written; zero force is commanded, forces are disabled, a `watchdog` fault is recorded and the
  /// loop stops. 0 turns the watchdog off.
  int watchdog_periods = 3;
  bool enable_forces_on_start = true;  ///< `start()` calls `device.enable_forces(true)`

  /// Throws InvalidArgument naming the field when a value is out of range.
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

enum class LoopFaultKind {
  none,
  watchdog,       ///< a tick overran by more than `watchdog_periods` periods
  communication,  ///< CommunicationError from the device
  safety,         ///< SafetyFault from the device or the callback
  device,         ///< another DeviceError
  callback,       ///< any other exception from the callback
};
[[nodiscard]] const char* to_string(LoopFaultKind kind) noexcept;

struct LoopFault {
  LoopFaultKind kind = LoopFaultKind::none;
  std::string message;  ///< the exception's what() (truncated to 127 bytes) or the watchdog's reason
  [[nodiscard]] explicit operator bool() const noexcept { return kind != LoopFaultKind::none; }
};

/// What the realtime settings gave (see `RealtimeMode`).
struct RealtimeStatus {
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
  std::uint64_t ticks = 0;             ///< callbacks completed
  std::uint64_t missed_deadlines = 0;  ///< ticks whose force was written after the next tick's start time
  std::uint64_t skipped_periods = 0;   ///< periods left out to get back on the deadline grid
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

/// Runs a callback on a dedicated thread at a fixed rate against a device. Not copyable or movable.
/// The device is used only by the loop thread between `start()` and the end of the run: do not touch
/// it from other threads meanwhile (the loop's thread start and join order the accesses).
class ServoLoop {
 public:
  /// `device` must outlive the loop. Throws InvalidArgument for bad options or an empty callback.
  ServoLoop(HapticDevice& device, ServoCallback callback, const ServoLoopOptions& options = {});
  /// Stops the loop (see `stop()`). Never throws.
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  /// Starts the loop thread: clears the statistics, locks memory when asked, enables forces when asked,
  /// applies the realtime settings on the new thread and returns once they are applied. Throws
  /// RealtimeError (mode `enforce`, with the reason), DeviceError (the device is not open, or from
  /// `enable_forces`), or Error when the loop is already running. A loop that ended (stopped by its
  /// callback, by `stop()` or by a fault) can be started again.
  void start();
  /// Asks the loop to stop, waits for the thread to end and returns the fault that ended the run, if
  /// any (none when it was stopped or ended by its callback). Forces are zero and disabled on return.
  /// Never throws; does nothing when not started. Called from the callback it only requests the stop (the
  /// callback should return `ServoCommand::stop` instead).
  LoopFault stop() noexcept;
  /// Waits until the loop ends by itself (its callback asked to stop, or a fault) and joins it; then
  /// rethrows the fault: the device's or the callback's own exception, or a SafetyFault for the
  /// watchdog. Returns normally when the run ended without a fault. Blocks forever if nothing ends it.
  void wait();
  /// True from `start()` until the loop thread has left its loop. Any thread.
  [[nodiscard]] bool running() const noexcept;
  /// A snapshot of the statistics; lock-free, from any thread while the loop runs or after it ended (not
  /// concurrently with `start()`, which resets them).
  [[nodiscard]] ServoLoopStats stats() const;
  [[nodiscard]] const ServoLoopOptions& options() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace calligraphy
