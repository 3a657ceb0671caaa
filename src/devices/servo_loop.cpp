#include "calligraphy/devices/servo_loop.hpp"

#include <sched.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/devices/device_servo_clock.hpp"
#include "core/library_log.hpp"
#include "core/rate_text.hpp"
#include "devices/latency_histogram.hpp"
#include "devices/log_queue.hpp"
#include "devices/servo_loop_realtime.hpp"

namespace calligraphy {

using devices::LatencyHistogram;
using devices::LogLevel;
using devices::LogRecord;

namespace {

constexpr double kMinRateHz = kMinServoRateHz;
constexpr double kMaxRateHz = kMaxRealTimeServoRateHz;

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Sleeps until the absolute CLOCK_MONOTONIC time `deadline_ns` (a signal does not shorten the sleep).
void sleep_until(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// What the loop thread logs; worded by `log_sink` on the drain thread.
enum LogCode : std::uint16_t {
  kDeadlineMissed = 1,
  kWatchdog,
  kFault,
  kStopped,
  kForceWithheld,
  kStoppedGrid
};

void log_sink(const LogRecord& r) {
  switch (r.code) {
    case kDeadlineMissed:
      calligraphy::detail::library_log().warn(
          "servo loop: tick {} missed its deadline by {:.1f} us ({} late so far)", r.count, r.values[0],
          static_cast<std::uint64_t>(r.values[1]));
      break;
    case kForceWithheld:
      calligraphy::detail::library_log().warn(
          "servo loop: tick {} withheld a force computed from a state {:.1f} us old ({} so far)", r.count,
          r.values[0], static_cast<std::uint64_t>(r.values[1]));
      break;
    case kWatchdog:
      calligraphy::detail::library_log().error("servo loop: watchdog at tick {}: stall of {:.1f} ms: {}",
                                               r.count, r.values[0], r.text.data());
      break;
    case kFault:
      calligraphy::detail::library_log().error("servo loop: fault at tick {}: {}", r.count, r.text.data());
      break;
    case kStopped:
      calligraphy::detail::library_log().info(
          "servo loop: stopped after {} ticks: {} late ticks, longest stall {:.3f} ms, {} forces withheld",
          r.count, static_cast<std::uint64_t>(r.values[0]), r.values[1],
          static_cast<std::uint64_t>(r.values[2]));
      break;
    case kStoppedGrid:
      calligraphy::detail::library_log().info(
          "servo loop: deadlines re-anchored {} times, {} deadlines skipped", r.count,
          static_cast<std::uint64_t>(r.values[0]));
      break;
    default:
      calligraphy::detail::library_log().debug("servo loop: log record {}", r.code);
  }
}

// True at the 1st, 2nd, 4th, 8th ... event: how often a recurring event is logged, so that a bad run
// cannot flood the queue or the log.
bool worth_logging(std::uint64_t count) noexcept { return (count & (count - 1)) == 0; }

constexpr double kMaxForceAgeLimitS = 1.0;

constexpr std::size_t kFaultMessageBytes = 128;

}  // namespace

const char* to_string(LoopFaultKind kind) noexcept {
  switch (kind) {
    case LoopFaultKind::none:
      return "none";
    case LoopFaultKind::watchdog:
      return "watchdog";
    case LoopFaultKind::device:
      return "device";
    case LoopFaultKind::callback:
      return "callback";
  }
  return "unknown";
}

void ServoLoopOptions::validate() const {
  if (!(rate_hz >= kMinRateHz && rate_hz <= kMaxRateHz)) {
    throw InvalidArgument("ServoLoopOptions.rate_hz = " + detail::rate_text(rate_hz) + " must be in " +
                          servo_rate_range_text(true));
  }
  if (priority < 0 || priority > 99) {
    throw InvalidArgument("ServoLoopOptions.priority = " + std::to_string(priority) + " must be in [0, 99]");
  }
  if (realtime == RealtimeMode::enforce && priority == 0) {
    throw InvalidArgument("ServoLoopOptions.priority must be in [1, 99] with RealtimeMode::enforce");
  }
  if (cpu < -1 || cpu >= CPU_SETSIZE) {
    throw InvalidArgument("ServoLoopOptions.cpu = " + std::to_string(cpu) +
                          " must be -1 or a CPU index below " + std::to_string(CPU_SETSIZE));
  }
  if (!(max_force_age_s > 0.0 && max_force_age_s <= kMaxForceAgeLimitS)) {
    throw InvalidArgument("ServoLoopOptions.max_force_age_s = " + shortest_decimal(max_force_age_s) +
                          " must be in (0, 1] s");
  }
  if (!(stall_timeout_s >= 0.0 && stall_timeout_s <= kMaxStallTimeoutS)) {
    throw InvalidArgument("ServoLoopOptions.stall_timeout_s = " + shortest_decimal(stall_timeout_s) +
                          " must be in [0, 60] s (0: no stall bound)");
  }
}

std::int64_t ServoLoopOptions::period_ns() const { return std::llround(1e9 / rate_hz); }

struct ServoLoop::Impl {
  Impl(HapticDevice& d, ServoCallback c, const ServoLoopOptions& o)
      : device(d), callback(std::move(c)), options(o) {}

  void run_thread() noexcept;
  static void on_device_frame(void* self) noexcept;
  void begin_run() noexcept;
  bool tick_once(std::int64_t wake, std::int64_t deadline) noexcept;
  void finish_run() noexcept;
  void stop_device_clock() noexcept;
  [[nodiscard]] bool clock_went_silent() const noexcept;
  void record_fault(LoopFaultKind kind, const char* message, std::uint64_t tick, double stall_ms = 0.0,
                    DeviceFault device_fault = DeviceFault::none) noexcept;
  void log(LogLevel level, std::uint16_t code, std::uint64_t count, double a = 0.0, double b = 0.0,
           const char* text = nullptr, double c = 0.0) noexcept {
    LogRecord r;
    r.level = level;
    r.code = code;
    r.time_ns = monotonic_ns();
    r.count = count;
    r.values = {a, b, c};
    if (text != nullptr) r.set_text(text);
    log_queue.try_push(r);  // a full queue drops the record and counts it; the loop never waits
  }
  void reset_stats() noexcept;
  [[nodiscard]] LoopFault fault() const;
  void check_rates(const DeviceServoClock* device_clock) const;

  HapticDevice& device;
  ServoCallback callback;
  std::function<void()> after_write;  // optional, on the loop thread after each tick's force write
  ServoLoopOptions options;
  double callback_rate_hz = 0.0;  // the rate the callback was built for; 0: it does not say
  std::string callback_rate_name;
  std::thread thread;
  // The loop thread's id while it runs (empty otherwise): how stop() knows it is called from the callback
  // without reading `thread`, which another thread's join may be writing.
  std::atomic<std::thread::id> loop_thread_id{};
  // Held by whoever starts the run or ends it (joins the thread, detaches the clock, stops the log drain):
  // stop() and wait() may be called from several threads at once, and only one may join.
  std::mutex control;
  // The device driver's servo thread while a run is attached to it; set and cleared by the controlling
  // thread, read by running() from any thread.
  std::atomic<DeviceServoClock*> clock{nullptr};
  devices::LogQueue log_queue;
  devices::LogDrain log_drain;

  std::atomic<bool> stop_requested{false};
  std::atomic<bool> running{false};
  // Start-up handshake: 0 pending, 1 the loop runs, 2 the realtime settings failed under `enforce`.
  std::atomic<int> startup{0};
  RealtimeStatus realtime;  // written before the handshake / by start(), read after it: ordered by `startup`

  // One run's state, touched only by whichever thread ticks (the loop's or the driver's) and by start()
  // before the first tick.
  struct RunState {
    std::int64_t period = 0;
    double period_s = 0.0;
    std::int64_t max_force_age_ns = 0;
    std::int64_t stall_limit_ns = 0;  // 0: no bound
    std::int64_t last_update = 0;     // the last force update the device got (start: forces just enabled)
    std::int64_t previous_wake = 0;
    std::uint64_t tick = 0;
    std::uint64_t late_count = 0;
    std::uint64_t withheld_count = 0;
    std::int64_t longest_stall = 0;
  } run;
  // The last time the driver called the frame function [ns, CLOCK_MONOTONIC]; read by other threads to
  // notice a driver that stopped calling.
  std::atomic<std::int64_t> last_frame_ns{0};
  std::atomic<std::thread::id> frame_thread{};  // the driver's thread, once it called

  // Statistics: single writer (the ticking thread), relaxed atomics for the readers.
  std::atomic<std::uint64_t> ticks{0};
  std::atomic<std::uint64_t> late{0};
  std::atomic<std::uint64_t> withheld{0};
  std::atomic<std::int64_t> longest_stall_ns{0};
  std::atomic<std::uint64_t> reanchors{0};
  std::atomic<std::uint64_t> skipped{0};
  std::atomic<std::uint64_t> wake_latency_max_ns{0};
  LatencyHistogram jitter{1000};        // 1 us bins
  LatencyHistogram callback_time{100};  // 0.1 us bins
  // The fault: message characters and device code first, then the kind with release; readers acquire
  // the kind.
  std::atomic<int> fault_kind{0};
  std::atomic<DeviceFault> fault_device{DeviceFault::none};
  std::array<std::atomic<char>, kFaultMessageBytes> fault_message{};
  std::exception_ptr fault_exception;  // set by the ticking thread, read after it ended
};

void ServoLoop::Impl::reset_stats() noexcept {
  ticks.store(0, std::memory_order_relaxed);
  late.store(0, std::memory_order_relaxed);
  withheld.store(0, std::memory_order_relaxed);
  longest_stall_ns.store(0, std::memory_order_relaxed);
  reanchors.store(0, std::memory_order_relaxed);
  skipped.store(0, std::memory_order_relaxed);
  wake_latency_max_ns.store(0, std::memory_order_relaxed);
  jitter.clear();
  callback_time.clear();
  fault_kind.store(0, std::memory_order_release);
  fault_device.store(DeviceFault::none, std::memory_order_relaxed);
  for (auto& c : fault_message) c.store('\0', std::memory_order_relaxed);
  fault_exception = nullptr;
}

void ServoLoop::Impl::record_fault(LoopFaultKind kind, const char* message, std::uint64_t tick,
                                   double stall_ms, DeviceFault device_fault) noexcept {
  std::size_t i = 0;
  if (message != nullptr) {
    for (; i + 1 < kFaultMessageBytes && message[i] != '\0'; ++i)
      fault_message[i].store(message[i], std::memory_order_relaxed);
  }
  fault_message[i].store('\0', std::memory_order_relaxed);
  fault_device.store(device_fault, std::memory_order_relaxed);
  fault_kind.store(static_cast<int>(kind), std::memory_order_release);
  log(LogLevel::error, kind == LoopFaultKind::watchdog ? kWatchdog : kFault, tick, stall_ms, 0.0, message);
}

LoopFault ServoLoop::Impl::fault() const {
  LoopFault f;
  f.kind = static_cast<LoopFaultKind>(fault_kind.load(std::memory_order_acquire));
  if (f.kind == LoopFaultKind::none) return f;
  f.device = fault_device.load(std::memory_order_relaxed);
  for (const auto& c : fault_message) {
    const char ch = c.load(std::memory_order_relaxed);
    if (ch == '\0') break;
    f.message.push_back(ch);
  }
  return f;
}

void ServoLoop::Impl::begin_run() noexcept {
  run = RunState{};
  run.period = options.period_ns();
  run.period_s = static_cast<double>(run.period) * 1e-9;
  run.max_force_age_ns = std::llround(options.max_force_age_s * 1e9);
  run.stall_limit_ns = std::llround(options.stall_timeout_s * 1e9);
  run.last_update = monotonic_ns();
  last_frame_ns.store(run.last_update, std::memory_order_relaxed);
}

// One tick: read, callback, the stale-force and stall guards, write, the after-write hook, statistics.
// `wake` is when the tick began (the state's age counts from there); the force must reach the device
// before `deadline`. False when the run ends with this tick (a fault, or the callback asked to stop).
bool ServoLoop::Impl::tick_once(std::int64_t wake, std::int64_t deadline) noexcept {
  double dt_s = run.period_s;
  if (run.tick > 0) {
    jitter.add(std::llabs((wake - run.previous_wake) - run.period));
    dt_s = static_cast<double>(wake - run.previous_wake) * 1e-9;
  }
  run.previous_wake = wake;

  bool stop_after = false;
  bool stalled = false;
  std::int64_t written = 0;
  std::int64_t stall = 0;
  std::int64_t force_age = 0;
  DeviceFault device_fault = DeviceFault::none;
  try {
    DeviceState state;
    device_fault = device.read_state(state);  // read at `wake`: the age of the state counts from there
    if (device_fault == DeviceFault::none) {
      const std::int64_t call = monotonic_ns();
      const ServoCommand command = callback(state, dt_s);
      const std::int64_t returned = monotonic_ns();
      callback_time.add(returned - call);
      stall = returned - run.last_update - run.period;
      force_age = returned - wake;
      stalled = run.stall_limit_ns > 0 && stall > run.stall_limit_ns;
      if (stalled || force_age > run.max_force_age_ns) {
        // Zero force is passive whatever the state; a force computed from an old state on a stiff fixture
        // is not (Colgate & Schenkel 1997).
        device_fault = device.write_force(Vec3::Zero());
        withheld.store(++run.withheld_count, std::memory_order_relaxed);
        if (!stalled && worth_logging(run.withheld_count)) {
          log(LogLevel::warn, kForceWithheld, run.tick + 1, static_cast<double>(force_age) * 1e-3,
              static_cast<double>(run.withheld_count));
        }
      } else {
        device_fault = device.write_force(command.force_n);
      }
      written = monotonic_ns();  // the device holds this force from here: stalls count from the write
      if (device_fault == DeviceFault::none && after_write && !command.stop && !stalled) after_write();
      stop_after = command.stop;
    }
  } catch (const std::exception& e) {
    fault_exception = std::current_exception();
    record_fault(LoopFaultKind::callback, e.what(), run.tick);
    return false;
  } catch (...) {
    fault_exception = std::current_exception();
    record_fault(LoopFaultKind::callback, "unknown exception from the servo callback", run.tick);
    return false;
  }
  if (device_fault != DeviceFault::none) {  // a code, not an exception: nothing allocated on this path
    record_fault(LoopFaultKind::device, to_string(device_fault), run.tick, 0.0, device_fault);
    return false;
  }
  run.last_update = written;
  ticks.store(++run.tick, std::memory_order_relaxed);
  if (stall > run.longest_stall) {
    run.longest_stall = stall;
    longest_stall_ns.store(stall, std::memory_order_relaxed);
  }
  if (written > deadline) {
    late.store(++run.late_count, std::memory_order_relaxed);
    if (worth_logging(run.late_count)) {
      log(LogLevel::warn, kDeadlineMissed, run.tick, static_cast<double>(written - deadline) * 1e-3,
          static_cast<double>(run.late_count));
    }
  }
  if (stalled) {  // counted above like any tick; the run ends here with zero force written
    record_fault(LoopFaultKind::watchdog, kStallFaultMessage, run.tick, static_cast<double>(stall) * 1e-6);
    return false;
  }
  return !stop_after;
}

// Whatever ended the run, the device is left with zero force and forces off. The transport may be gone (a
// fault code then): disabling below is the next line of defence.
void ServoLoop::Impl::finish_run() noexcept {
  static_cast<void>(device.write_force(Vec3::Zero()));
  try {
    device.enable_forces(false);
  } catch (...) {
  }
  log(LogLevel::info, kStopped, run.tick, static_cast<double>(run.late_count),
      static_cast<double>(run.longest_stall) * 1e-6, nullptr, static_cast<double>(run.withheld_count));
  log(LogLevel::info, kStoppedGrid, reanchors.load(std::memory_order_relaxed),
      static_cast<double>(skipped.load(std::memory_order_relaxed)));
  running.store(false, std::memory_order_release);
  running.notify_all();
}

// The loop's own clock. Deadlines are absolute, on a grid of whole periods: a tick that is a little late
// does not shift later ones. A tick that ends past the next deadline re-anchors the grid one period after
// its own end, so missed ticks are never run back to back and the callback's dt stays about a period after
// the first tick behind a stall. What a late tick writes: see ServoLoopOptions.
void ServoLoop::Impl::run_thread() noexcept {
  begin_run();
  const std::int64_t period = run.period;
  std::int64_t next = run.last_update + period;
  while (!stop_requested.load(std::memory_order_acquire)) {
    sleep_until(next);
    const std::int64_t wake = monotonic_ns();
    if (wake - next > static_cast<std::int64_t>(wake_latency_max_ns.load(std::memory_order_relaxed))) {
      wake_latency_max_ns.store(static_cast<std::uint64_t>(wake - next), std::memory_order_relaxed);
    }
    if (!tick_once(wake, next + period)) break;  // the force must be out before the next tick starts
    next += period;
    if (run.last_update >= next) {  // behind: the deadlines that passed are dropped, the grid restarts
      const std::int64_t passed = (run.last_update - next) / period + 1;
      next = run.last_update + period;
      skipped.store(skipped.load(std::memory_order_relaxed) + static_cast<std::uint64_t>(passed),
                    std::memory_order_relaxed);
      reanchors.store(reanchors.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    }
  }
  finish_run();
}

// The device's clock: one tick per driver frame, in the frame that read the state, so the force answers
// that state in the same frame. The driver's own jitter is the period jitter; there is no deadline grid
// to re-anchor (the driver keeps its own).
void ServoLoop::Impl::on_device_frame(void* self) noexcept {
  Impl& m = *static_cast<Impl*>(self);
  if (!m.running.load(std::memory_order_acquire)) return;  // the run ended; the driver still frames
  const std::int64_t wake = monotonic_ns();
  m.last_frame_ns.store(wake, std::memory_order_relaxed);
  m.frame_thread.store(std::this_thread::get_id(), std::memory_order_relaxed);
  if (m.stop_requested.load(std::memory_order_acquire) || !m.tick_once(wake, wake + m.run.period)) {
    m.finish_run();
  }
}

// True when the driver has not called for longer than the stall bound (plus a period): its clock stopped,
// and no tick will notice. Off when the stall bound is off.
bool ServoLoop::Impl::clock_went_silent() const noexcept {
  if (clock.load(std::memory_order_acquire) == nullptr || options.stall_timeout_s <= 0.0) return false;
  const std::int64_t silent = monotonic_ns() - last_frame_ns.load(std::memory_order_relaxed);
  return silent > std::llround(options.stall_timeout_s * 1e9) + options.period_ns();
}

// Ends a run on the device's clock from a normal thread: asks the next frame to finish it, waits for that
// (a few periods), detaches, and finishes it here when the driver stopped calling (a stall then).
void ServoLoop::Impl::stop_device_clock() noexcept {
  stop_requested.store(true, std::memory_order_release);
  const std::int64_t wait_until =
      monotonic_ns() + std::max<std::int64_t>(100'000'000, 10 * options.period_ns());  // 100 ms at least
  while (running.load(std::memory_order_acquire) && monotonic_ns() < wait_until && !clock_went_silent()) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  clock.load(std::memory_order_acquire)->detach();  // no frame runs after this returns
  clock.store(nullptr, std::memory_order_release);
  if (running.load(std::memory_order_acquire)) {
    const std::int64_t silent_ns = monotonic_ns() - last_frame_ns.load(std::memory_order_relaxed);
    const double silent_ms = static_cast<double>(silent_ns) * 1e-6;
    // The device held the last frame's force all the while the driver did not call: a stall like one
    // between two ticks (the time beyond one period), counted in the statistics the run reports.
    const std::int64_t stall = silent_ns - options.period_ns();
    if (stall > run.longest_stall) {
      run.longest_stall = stall;
      longest_stall_ns.store(stall, std::memory_order_relaxed);
    }
    if (options.stall_timeout_s > 0.0 && silent_ms > options.stall_timeout_s * 1e3 &&
        fault_kind.load(std::memory_order_acquire) == 0) {
      record_fault(LoopFaultKind::watchdog, kStallFaultMessage, run.tick, silent_ms);
    }
    finish_run();
  }
}

ServoLoop::ServoLoop(HapticDevice& device, ServoCallback callback, const ServoLoopOptions& options,
                     AfterForceWrite after_write)
    : ServoLoop(device, Prepared{std::move(callback), 0.0, ""}, options, std::move(after_write)) {}

ServoLoop::ServoLoop(HapticDevice& device, Prepared prepared, const ServoLoopOptions& options,
                     AfterForceWrite after_write) {
  options.validate();
  if (!prepared.callback) throw InvalidArgument("ServoLoop: the callback is empty");
  impl_ = std::make_unique<Impl>(device, std::move(prepared.callback), options);
  impl_->after_write = std::move(after_write);
  impl_->callback_rate_hz = prepared.rate_hz;
  // A callback that names no place for its rate (nullptr or "") is still told which rate to change.
  const bool named = prepared.rate_name != nullptr && *prepared.rate_name != '\0';
  impl_->callback_rate_name = named ? prepared.rate_name : "the callback's servo_rate_hz()";
}

ServoLoop::~ServoLoop() { stop(); }

// A loop, a device clock and a callback built for one rate must agree: a renderer stepped at another rate
// runs its time-based parts (fades, filters, a replay) at the wrong speed, which no measurement after the run
// could tell from a loaded machine.
void ServoLoop::Impl::check_rates(const DeviceServoClock* device_clock) const {
  // Written so that a NaN rate differs from every rate (a NaN compares false either way round).
  const auto differ = [](double a, double b) { return !(std::abs(a - b) <= 1e-6 * std::abs(b)); };
  const bool says_rate = callback_rate_hz != 0.0;  // 0: it does not say; any other value is checked
  if (device_clock != nullptr) {
    const double clock_hz = device_clock->servo_rate_hz();
    if (says_rate && differ(callback_rate_hz, clock_hz)) {
      throw InvalidArgument(
          "ServoLoop::start: the callback was built for " + detail::rate_text(callback_rate_hz) + " (" +
          callback_rate_name + "), but '" + device.info().model + "' runs its own servo clock at " +
          detail::rate_text(clock_hz) + ": set " + callback_rate_name + " to " + detail::rate_text(clock_hz));
    }
    if (differ(options.rate_hz, clock_hz)) {
      throw InvalidArgument("ServoLoop::start: ServoLoopOptions::rate_hz is " +
                            detail::rate_text(options.rate_hz) + ", but '" + device.info().model +
                            "' runs its own servo clock at " + detail::rate_text(clock_hz) +
                            ": ask for that rate");
    }
  }
  if (says_rate && differ(callback_rate_hz, options.rate_hz)) {
    throw InvalidArgument("ServoLoop::start: the callback was built for " +
                          detail::rate_text(callback_rate_hz) + " (" + callback_rate_name +
                          "), but the loop runs at " + detail::rate_text(options.rate_hz) +
                          " (ServoLoopOptions::rate_hz): set both to one rate");
  }
}

void ServoLoop::start() {
  Impl& m = *impl_;
  const std::lock_guard control(m.control);
  if (m.running.load(std::memory_order_acquire))
    throw StateError("ServoLoop::start: the loop is already running");
  if (m.thread.joinable()) m.thread.join();              // the previous run ended by itself
  if (m.clock.load() != nullptr) m.stop_device_clock();  // the previous run ended by itself
  m.log_drain.stop();
  if (!m.device.is_open())
    throw DeviceError("ServoLoop::start: the device '" + m.device.info().model + "' is not open");
  DeviceServoClock* const device_clock = m.device.servo_clock();
  m.check_rates(device_clock);

  m.frame_thread.store(std::thread::id{}, std::memory_order_relaxed);
  m.startup.store(0, std::memory_order_release);  // readers stop copying the previous run's realtime status
  m.reset_stats();
  m.realtime = RealtimeStatus{};
  m.realtime.device_clock = device_clock != nullptr;
  if (m.options.lock_memory) {
    m.realtime.memory_locked = devices::lock_process_memory(m.realtime.problems);
    if (!m.realtime.memory_locked && m.options.realtime == RealtimeMode::enforce) {
      throw RealtimeError("ServoLoop::start: realtime required but " + m.realtime.problems);
    }
  }
  if (m.options.enable_forces_on_start) m.device.enable_forces(true);

  m.stop_requested.store(false, std::memory_order_relaxed);
  m.running.store(true, std::memory_order_release);
  // A thread the system will not start (the threads this user may run, RLIMIT_NPROC, or the memory of its
  // stack used up) ends the start as any refusal does: not running, forces off, one error naming the cause.
  const auto refuse_thread = [&m](const std::system_error& e) {
    m.running.store(false, std::memory_order_release);
    m.log_drain.stop();
    try {
      m.device.enable_forces(false);
    } catch (...) {
    }
    throw Error(
        std::string("ServoLoop::start: cannot start a thread: ") + e.code().message() +
        " (the threads this user may run, RLIMIT_NPROC, or the memory of a thread's stack are used up)");
  };
  // The library's logger is registered on first use; do it here, before the drain thread logs.
  static_cast<void>(calligraphy::detail::library_log());
  try {
    m.log_drain.start(m.log_queue, log_sink);
  } catch (const std::system_error& e) {
    refuse_thread(e);
  }
  if (device_clock != nullptr) {
    // The driver's thread ticks: its priority and CPU are the driver's to set, not the loop's.
    m.begin_run();
    try {
      device_clock->attach(&Impl::on_device_frame, &m);
    } catch (...) {
      m.running.store(false, std::memory_order_release);
      m.log_drain.stop();
      try {
        m.device.enable_forces(false);
      } catch (...) {
      }
      throw;
    }
    m.clock.store(device_clock, std::memory_order_release);
    m.startup.store(1, std::memory_order_release);
    calligraphy::detail::library_log().debug(
        "servo loop: started on the device's own servo clock at {} Hz (the driver's thread); memory "
        "locked {}",
        m.options.rate_hz, m.realtime.memory_locked ? "yes" : "no");
    return;
  }
  try {
    m.thread = std::thread([&m] {
      m.loop_thread_id.store(std::this_thread::get_id(), std::memory_order_release);
      devices::apply_thread_realtime(m.options, m.realtime);
      const bool failed = m.options.realtime == RealtimeMode::enforce && !m.realtime.problems.empty();
      if (failed) {
        m.loop_thread_id.store(std::thread::id{}, std::memory_order_release);
        m.running.store(false, std::memory_order_release);
        m.startup.store(2, std::memory_order_release);
        m.startup.notify_one();
        return;
      }
      devices::prefault_stack();
      m.startup.store(1, std::memory_order_release);
      m.startup.notify_one();
      m.run_thread();
      m.loop_thread_id.store(std::thread::id{}, std::memory_order_release);
    });
  } catch (const std::system_error& e) {
    refuse_thread(e);
  }
  m.startup.wait(0, std::memory_order_acquire);
  if (m.startup.load(std::memory_order_acquire) == 2) {
    m.thread.join();
    m.log_drain.stop();
    try {
      m.device.enable_forces(false);
    } catch (...) {
    }
    throw RealtimeError("ServoLoop::start: realtime required but " + m.realtime.problems);
  }
  // Debug, not info: an application that starts a loop per trial would get a line per trial.
  calligraphy::detail::library_log().debug(
      "servo loop: started at {} Hz; SCHED_FIFO {}, CPU {}, memory locked {}{}{}", m.options.rate_hz,
      m.realtime.fifo_scheduling ? std::to_string(m.realtime.priority) : "no",
      m.realtime.cpu >= 0 ? std::to_string(m.realtime.cpu) : "not pinned",
      m.realtime.memory_locked ? "yes" : "no",
      m.realtime.problems.empty() ? "" : "; not obtained: ", m.realtime.problems);
}

LoopFault ServoLoop::stop() noexcept {
  Impl& m = *impl_;
  m.stop_requested.store(true, std::memory_order_release);
  if (m.loop_thread_id.load(std::memory_order_acquire) == std::this_thread::get_id() ||
      (m.clock.load() != nullptr && m.frame_thread.load() == std::this_thread::get_id()))
    return {};  // called from the callback: stops after this tick
  // Another thread may be in stop() or wait() too: it ends the run, and this call then finds it ended.
  const std::lock_guard control(m.control);
  if (m.thread.joinable()) m.thread.join();
  if (m.clock.load() != nullptr) m.stop_device_clock();
  m.log_drain.stop();
  try {
    return m.fault();
  } catch (...) {  // out of memory copying the message
    return LoopFault{static_cast<LoopFaultKind>(m.fault_kind.load(std::memory_order_acquire)),
                     m.fault_device.load(std::memory_order_relaxed),
                     {}};
  }
}

void ServoLoop::wait() {
  Impl& m = *impl_;
  const std::lock_guard control(m.control);  // as stop(): one thread ends the run
  if (m.thread.joinable()) m.thread.join();
  if (m.clock.load() != nullptr) {
    // The driver ends the run in one of its frames; a driver that stopped calling is a stall. A stop()
    // from another thread (waiting for this lock) ends the run here.
    while (m.running.load(std::memory_order_acquire) && !m.clock_went_silent() &&
           !m.stop_requested.load(std::memory_order_acquire)) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    m.stop_device_clock();
  }
  m.log_drain.stop();
  const LoopFault f = m.fault();
  if (!f) return;
  if (f.kind == LoopFaultKind::device) throw_device_fault(f.device, m.device.info().model);
  if (m.fault_exception) std::rethrow_exception(m.fault_exception);
  throw SafetyFault(f.message);
}

bool ServoLoop::running() const noexcept {
  // On a device's clock, a driver that stopped calling leaves no thread to notice: the run counts as over
  // (stop() then records the stall) once the silence passes the stall bound.
  return impl_->running.load(std::memory_order_acquire) && !impl_->clock_went_silent();
}

const ServoLoopOptions& ServoLoop::options() const noexcept { return impl_->options; }

ServoLoopStats ServoLoop::stats() const {
  const Impl& m = *impl_;
  ServoLoopStats s;
  s.running = m.running.load(std::memory_order_acquire);
  s.rate_hz = m.options.rate_hz;
  s.ticks = m.ticks.load(std::memory_order_relaxed);
  s.late_ticks = m.late.load(std::memory_order_relaxed);
  s.missed_deadlines = s.late_ticks;
  s.forces_withheld = m.withheld.load(std::memory_order_relaxed);
  s.longest_stall_s = static_cast<double>(m.longest_stall_ns.load(std::memory_order_relaxed)) * 1e-9;
  s.deadline_reanchors = m.reanchors.load(std::memory_order_relaxed);
  s.skipped_periods = m.skipped.load(std::memory_order_relaxed);
  s.period_jitter_us_p50 = m.jitter.quantile_ns(0.50) * 1e-3;
  s.period_jitter_us_p99 = m.jitter.quantile_ns(0.99) * 1e-3;
  s.period_jitter_us_max = static_cast<double>(m.jitter.max_ns()) * 1e-3;
  s.wake_latency_us_max = static_cast<double>(m.wake_latency_max_ns.load(std::memory_order_relaxed)) * 1e-3;
  s.callback_us_mean = m.callback_time.mean_ns() * 1e-3;
  s.callback_us_p99 = m.callback_time.quantile_ns(0.99) * 1e-3;
  s.callback_us_max = static_cast<double>(m.callback_time.max_ns()) * 1e-3;
  for (std::size_t i = 0; i < LatencyHistogram::kBins; ++i) {
    if (const std::uint64_t n = m.jitter.bin_count(i); n > 0) {
      s.period_jitter_histogram.push_back({static_cast<double>(m.jitter.upper_ns(i)) * 1e-3, n});
    }
  }
  if (m.startup.load(std::memory_order_acquire) != 0) s.realtime = m.realtime;
  s.fault = m.fault();
  return s;
}

}  // namespace calligraphy
