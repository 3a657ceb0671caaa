// hd_stand_in_scheduler.cpp - the servo thread of the stand-in libHD.so:
// tick timing, hand playback, injected faults, callback scheduling and the
// per-tick frame log.
#include <pthread.h>
#include <sched.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>
#include <thread>

#include "hd_stand_in_state.h"

namespace hdsi {
namespace {

constexpr std::int64_t kNsPerS = 1000000000LL;

timespec to_timespec(std::int64_t ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(ns % kNsPerS);
  return ts;
}

void sleep_until(std::int64_t deadline_ns) {
  const timespec ts = to_timespec(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// Sleeps until deadline_ns in short pieces so that a stop request is honoured.
void sleep_until_or_stop(std::int64_t deadline_ns) {
  Lib& L = lib();
  constexpr std::int64_t kSlice = 20 * 1000000LL;
  while (!L.stop.load(std::memory_order_acquire)) {
    const std::int64_t now = mono_ns();
    if (now >= deadline_ns) return;
    sleep_until(deadline_ns - now > kSlice ? now + kSlice : deadline_ns);
  }
}

// Hand position at time t (s) along the path: linear interpolation, held at
// both ends. A coordinate that is not finite at either end of its segment is
// the segment's first point's, held (a garbled reading is played as given,
// never turned into another by the interpolation). Caller holds state_mu.
Vec3 path_position(const Lib& L, double t) {
  const std::size_t n = L.path_t.size();
  if (n == 0) return {0.0, 0.0, 0.0};
  auto point = [&](std::size_t i) {
    return Vec3{L.path_xyz[3 * i], L.path_xyz[3 * i + 1], L.path_xyz[3 * i + 2]};
  };
  if (t <= L.path_t[0]) return point(0);
  if (t >= L.path_t[n - 1]) return point(n - 1);
  std::size_t lo = 0;
  std::size_t hi = n - 1;  // path_t[lo] <= t < path_t[hi]
  while (hi - lo > 1) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (L.path_t[mid] <= t) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const double span = L.path_t[hi] - L.path_t[lo];
  const double a = span > 0.0 ? (t - L.path_t[lo]) / span : 1.0;
  const Vec3 p0 = point(lo);
  const Vec3 p1 = point(hi);
  Vec3 p{};
  for (std::size_t i = 0; i < 3; ++i) {
    p[i] = std::isfinite(p0[i]) && std::isfinite(p1[i]) ? p0[i] + a * (p1[i] - p0[i]) : p0[i];
  }
  return p;
}

struct TickInputs {
  Vec3 hand{};
  double slow_ms = 0.0;
  bool link_lost = false;
  bool link_restored = false;
  bool force_limit = false;
};

// Reads the hand and the faults due at tick k. Called on the servo thread.
TickInputs gather_inputs(long k) {
  Lib& L = lib();
  Servo& S = L.servo;
  TickInputs in;
  std::lock_guard<std::mutex> lock(L.state_mu);
  if (S.path_epoch_seen != L.path_epoch) {
    S.path_epoch_seen = L.path_epoch;
    S.path_time_s = 0.0;
  }
  if (S.wave_epoch_seen != L.wave_epoch) {
    S.wave_epoch_seen = L.wave_epoch;
    S.wave_ticks = 0;
  }
  in.hand = path_position(L, S.path_time_s);
  if (L.wave_half > 0 && L.wave_amp_mm != 0.0 && L.wave_axis >= 0 && L.wave_axis < 3) {
    if ((S.wave_ticks / L.wave_half) % 2 == 1)
      in.hand[static_cast<std::size_t>(L.wave_axis)] += L.wave_amp_mm;
  }
  for (Fault& f : L.faults) {
    if (!f.used || f.tick > k) continue;
    switch (f.kind) {
      case HD_STAND_IN_FAULT_LINK_LOST:
        in.link_lost = true;
        break;
      case HD_STAND_IN_FAULT_LINK_RESTORED:
        in.link_restored = true;
        break;
      case HD_STAND_IN_FAULT_FORCE_LIMIT:
        in.force_limit = true;
        break;
      case HD_STAND_IN_FAULT_SLOW_FRAME:
        in.slow_ms += f.value;
        break;
      default:
        continue;  // not a servo-side fault (scheduler full)
    }
    f.used = false;
  }
  return in;
}

// Moves the device state to tick k's values.
void update_device(const TickInputs& in, double rate_hz) {
  Lib& L = lib();
  Servo& S = L.servo;
  if (in.link_restored) L.link_lost.store(false);
  if (in.link_lost) L.link_lost.store(true);
  FrameView& v = S.view;
  v.last_pos = v.pos;
  v.last_vel = v.vel;
  v.last_buttons = v.buttons;
  v.last_ink = v.ink;
  v.force = {0.0, 0.0, 0.0};
  if (L.link_lost.load()) {
    // Nothing new arrives from the arm: the pose freezes.
    v.vel = {0.0, 0.0, 0.0};
    return;
  }
  v.pos = in.hand;
  for (std::size_t i = 0; i < 3; ++i) v.vel[i] = S.have_prev ? (v.pos[i] - v.last_pos[i]) * rate_hz : 0.0;
  v.buttons = L.buttons.load();
  const bool docked = L.docked.load();
  const bool reads_one = L.docked_reads_one.load();
  v.ink = docked == reads_one ? 1 : 0;
  if (!S.have_prev) {  // first tick of a run: "last" is the same sample
    v.last_pos = v.pos;
    v.last_vel = v.vel;
    v.last_buttons = v.buttons;
    v.last_ink = v.ink;
  }
  S.have_prev = true;
}

struct Pending {
  HDSchedulerHandle handle;
  HDSchedulerCallback fn;
  void* data;
  HDushort priority;
  unsigned long seq;
};

Callback* find_callback(Lib& L, HDSchedulerHandle h) {
  for (Callback& c : L.callbacks) {
    if (c.used && c.handle == h) return &c;
  }
  return nullptr;
}

// Runs every scheduled callback once, higher priority first, in scheduling
// order within a priority.
void run_callbacks() {
  Lib& L = lib();
  std::array<Pending, kMaxCallbacks> list{};
  std::size_t n = 0;
  {
    std::lock_guard<std::mutex> lock(L.sched_mu);
    for (const Callback& c : L.callbacks) {
      if (c.used) list[n++] = Pending{c.handle, c.fn, c.data, c.priority, c.seq};
    }
  }
  for (std::size_t i = 1; i < n; ++i) {  // insertion sort, no allocation
    const Pending p = list[i];
    std::size_t j = i;
    while (j > 0 && (list[j - 1].priority < p.priority ||
                     (list[j - 1].priority == p.priority && list[j - 1].seq > p.seq))) {
      list[j] = list[j - 1];
      --j;
    }
    list[j] = p;
  }
  for (std::size_t i = 0; i < n; ++i) {
    {
      std::lock_guard<std::mutex> lock(L.sched_mu);
      if (find_callback(L, list[i].handle) == nullptr) continue;  // unscheduled meanwhile
      L.running_cb = list[i].handle;
    }
    const HDCallbackCode code = list[i].fn(list[i].data);
    std::lock_guard<std::mutex> lock(L.sched_mu);
    L.running_cb = 0;
    if (code == HD_CALLBACK_DONE) {
      if (Callback* c = find_callback(L, list[i].handle)) c->used = false;
    }
    if (L.waiters > 0) L.sched_cv.notify_all();
  }
}

void end_tick() {
  Lib& L = lib();
  Servo& S = L.servo;
  if (S.frame_open) {
    S.frame_open = false;
    violation(HD_STAND_IN_VIOLATION_FRAME_LEFT_OPEN, HD_FRAME_ERROR);
    S.output = false;
    S.out = {0.0, 0.0, 0.0};
  }
  if (S.force_limit_pending) {  // no frame consumed it: report at tick end
    S.force_limit_pending = false;
    L.force_output.store(false);
    push_error(HD_EXCEEDED_MAX_FORCE, HD_STAND_IN_INTERNAL_FAULT_BASE + HD_STAND_IN_FAULT_FORCE_LIMIT);
    S.output = false;
    S.out = {0.0, 0.0, 0.0};
  }
  hd_stand_in_frame_record rec{};
  rec.tick = S.tick;
  rec.device_time_s = device_time_s(S.start_ns);
  for (std::size_t i = 0; i < 3; ++i) {
    rec.position_mm[i] = S.view.pos[i];
    rec.velocity_mm_s[i] = S.view.vel[i];
    rec.force_set_n[i] = S.force_set ? S.view.force[i] : 0.0;
    rec.force_output_n[i] = S.output ? S.out[i] : 0.0;
  }
  rec.buttons = S.view.buttons;
  rec.inkwell_switch = S.view.ink;
  rec.frames = S.frames_done;
  rec.position_read = S.position_read ? 1 : 0;
  rec.force_set = S.force_set ? 1 : 0;
  rec.force_output = S.output ? 1 : 0;
  rec.first_error = S.first_error;
  rec.error_count = S.error_count;
  rec.late_us = S.late_us;
  std::lock_guard<std::mutex> lock(L.log_mu);
  if (!L.ring.empty()) L.ring[static_cast<std::size_t>(S.tick) % L.ring.size()] = rec;
  L.published = S.view;
  if (!S.output) L.published.force = {0.0, 0.0, 0.0};
}

void servo_main() {
  tl_on_servo = true;
  // HDAPI runs its servo loop in a thread of its own at high priority (OpenHaptics Programmer's Guide):
  // the stand-in asks for SCHED_FIFO where the process may have it (root, CAP_SYS_NICE) and ticks at normal
  // priority where not, so that other work on a busy machine delays its ticks no more than the driver's.
  sched_param priority{};
  priority.sched_priority = sched_get_priority_min(SCHED_FIFO) + 10;
  (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority);
  Lib& L = lib();
  Servo& S = L.servo;
  std::int64_t deadline = mono_ns();
  std::int64_t prev_start = 0;
  bool first = true;
  if (environment_faults().scheduler_stalled) {  // HD_STAND_IN_SCHEDULER_STALLED: alive, never ticks
    while (!L.stop.load(std::memory_order_acquire)) sleep_until(mono_ns() + 1'000'000);
    return;
  }
  while (!L.stop.load(std::memory_order_acquire)) {
    const unsigned long rate = L.rate_hz.load();
    const std::int64_t period = kNsPerS / static_cast<std::int64_t>(rate);
    if (!first) deadline += period;
    sleep_until(deadline);
    if (L.stop.load(std::memory_order_acquire)) break;

    const long k = L.ticks.load(std::memory_order_relaxed);
    const TickInputs in = gather_inputs(k);
    if (in.slow_ms > 0.0) {
      sleep_until_or_stop(mono_ns() + static_cast<std::int64_t>(in.slow_ms * 1e6));
      if (L.stop.load(std::memory_order_acquire)) break;
    }
    const std::int64_t now = mono_ns();
    const std::int64_t late = now - deadline;
    if (late > period) deadline = now;  // overran: re-base instead of bursting to catch up
    L.tick_start_ns.store(now);
    if (!first && now > prev_start) {
      L.instantaneous_rate.store(static_cast<double>(kNsPerS) / static_cast<double>(now - prev_start));
    }
    prev_start = now;
    first = false;

    S.tick = k;
    S.start_ns = now;
    S.late_us = static_cast<long>(late / 1000);
    S.frame_open = false;
    S.frames_done = 0;
    S.position_read = false;
    S.force_set = false;
    S.output = false;
    S.out = {0.0, 0.0, 0.0};
    S.first_error = HD_SUCCESS;
    S.error_count = 0;
    S.force_limit_pending = in.force_limit;
    update_device(in, static_cast<double>(rate));

    run_callbacks();
    end_tick();

    S.path_time_s += 1.0 / static_cast<double>(rate);
    ++S.wave_ticks;
    L.ticks.store(k + 1, std::memory_order_release);
  }
  tl_on_servo = false;
}

}  // namespace

void stop_scheduler_internal() {
  Lib& L = lib();
  std::lock_guard<std::mutex> life(L.life_mu);
  if (!L.thread.joinable()) return;
  L.stop.store(true, std::memory_order_release);
  L.thread.join();
  L.running.store(false);
  L.tick_start_ns.store(0);
  std::lock_guard<std::mutex> lock(L.sched_mu);
  // Synchronous callers must not wait for a scheduler that is gone.
  for (Callback& c : L.callbacks) {
    if (c.used && c.sync) c.used = false;
  }
  L.sched_cv.notify_all();
}

void clear_callbacks() {
  Lib& L = lib();
  std::lock_guard<std::mutex> lock(L.sched_mu);
  for (Callback& c : L.callbacks) c.used = false;
  L.next_handle = 1;
  L.next_seq = 0;
  L.sched_cv.notify_all();
}

int scheduled_count() {
  Lib& L = lib();
  std::lock_guard<std::mutex> lock(L.sched_mu);
  int n = 0;
  for (const Callback& c : L.callbacks) n += c.used ? 1 : 0;
  return n;
}

namespace {

// Consumes one injected "scheduler full" failure if one is due.
bool scheduler_full_injected() {
  Lib& L = lib();
  const long now = L.ticks.load(std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(L.state_mu);
  for (Fault& f : L.faults) {
    if (f.used && f.kind == HD_STAND_IN_FAULT_SCHEDULER_FULL && f.tick <= now && f.remaining > 0) {
      if (--f.remaining == 0) f.used = false;
      return true;
    }
  }
  return false;
}

// Adds a callback; returns its handle or kInvalidSchedulerHandle (error pushed).
HDSchedulerHandle add_callback(HDSchedulerCallback fn, void* data, HDushort priority, bool sync) {
  Lib& L = lib();
  if (fn == nullptr) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return kInvalidSchedulerHandle;
  }
  if (scheduler_full_injected()) {
    push_error(HD_SCHEDULER_FULL, HD_STAND_IN_INTERNAL_FAULT_BASE + HD_STAND_IN_FAULT_SCHEDULER_FULL);
    return kInvalidSchedulerHandle;
  }
  std::lock_guard<std::mutex> lock(L.sched_mu);
  for (Callback& c : L.callbacks) {
    if (c.used) continue;
    c = Callback{true, sync, L.next_handle++, fn, data, priority, L.next_seq++};
    if (L.next_handle == kInvalidSchedulerHandle || L.next_handle == 0) L.next_handle = 1;
    return c.handle;
  }
  push_error(HD_SCHEDULER_FULL, HD_STAND_IN_INTERNAL_API);
  return kInvalidSchedulerHandle;
}

}  // namespace
}  // namespace hdsi

using namespace hdsi;

extern "C" {

void hdStartScheduler(void) {
  Lib& L = lib();
  if (tl_on_servo) return;  // already running: we are inside it
  std::lock_guard<std::mutex> life(L.life_mu);
  if (L.thread.joinable()) return;  // already running
  if (!L.initialized.load()) {
    push_error(HD_INVALID_OPERATION, HD_STAND_IN_INTERNAL_API);  // no device to clock the loop
    return;
  }
  Servo& S = L.servo;
  S = Servo{};
  // t = 0 of the path and of the square wave is the first tick of this run.
  {
    std::lock_guard<std::mutex> lock(L.state_mu);
    S.path_epoch_seen = L.path_epoch;
    S.wave_epoch_seen = L.wave_epoch;
  }
  L.stop.store(false, std::memory_order_release);
  L.running.store(true);
  L.thread = std::thread(servo_main);
}

void hdStopScheduler(void) {
  if (tl_on_servo) {
    violation(HD_STAND_IN_VIOLATION_BLOCKING_ON_SERVO, HD_INVALID_OPERATION);
    return;
  }
  if (environment_faults().stop_hangs) {  // HD_STAND_IN_STOP=hang: stuck for good, as a wedged driver is
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  stop_scheduler_internal();
}

void hdSetSchedulerRate(HDulong nRate) {
  if (nRate != 500 && nRate != 1000 && nRate != 2000) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  lib().rate_hz.store(nRate);
}

HDdouble hdGetSchedulerTimeStamp(void) {
  Lib& L = lib();
  if (!L.running.load()) return 0.0;
  const std::int64_t start = L.tick_start_ns.load();
  if (start == 0) return 0.0;
  const std::int64_t now = mono_ns();
  return now > start ? static_cast<double>(now - start) * 1e-9 : 0.0;
}

HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority) {
  return add_callback(pCallback, pUserData, nPriority, false);
}

void hdScheduleSynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority) {
  Lib& L = lib();
  if (tl_on_servo) {  // would wait for the thread it runs on
    violation(HD_STAND_IN_VIOLATION_BLOCKING_ON_SERVO, HD_INVALID_OPERATION);
    return;
  }
  if (!L.running.load()) {
    push_error(HD_INVALID_OPERATION, HD_STAND_IN_INTERNAL_API);  // documented: not run
    return;
  }
  const HDSchedulerHandle h = add_callback(pCallback, pUserData, nPriority, true);
  if (h == kInvalidSchedulerHandle) return;
  std::unique_lock<std::mutex> lock(L.sched_mu);
  ++L.waiters;
  L.sched_cv.wait(lock, [&] { return find_callback(L, h) == nullptr || !L.running.load(); });
  --L.waiters;
  if (Callback* c = find_callback(L, h)) {  // scheduler stopped before it ran
    c->used = false;
    lock.unlock();
    push_error(HD_INVALID_OPERATION, HD_STAND_IN_INTERNAL_API);
  }
}

void hdUnschedule(HDSchedulerHandle hHandle) {
  Lib& L = lib();
  std::unique_lock<std::mutex> lock(L.sched_mu);
  Callback* c = find_callback(L, hHandle);
  if (c == nullptr) return;  // unknown or already finished: nothing to do
  c->used = false;
  L.sched_cv.notify_all();  // a synchronous caller of it returns
  if (tl_on_servo) return;  // from a callback: it cannot be running concurrently
  ++L.waiters;
  L.sched_cv.wait(lock, [&] { return L.running_cb != hHandle; });
  --L.waiters;
}

HDboolean hdWaitForCompletion(HDSchedulerHandle hHandle, HDWaitCode param) {
  Lib& L = lib();
  std::unique_lock<std::mutex> lock(L.sched_mu);
  if (param != HD_WAIT_CHECK_STATUS && param != HD_WAIT_INFINITE) {
    lock.unlock();
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return HD_FALSE;
  }
  bool scheduled = find_callback(L, hHandle) != nullptr;
  if (param == HD_WAIT_INFINITE && scheduled) {
    if (tl_on_servo) {
      lock.unlock();
      violation(HD_STAND_IN_VIOLATION_BLOCKING_ON_SERVO, HD_INVALID_OPERATION);
      return HD_TRUE;
    }
    ++L.waiters;
    // A stopped scheduler would never finish it: return instead of hanging.
    L.sched_cv.wait(lock, [&] { return find_callback(L, hHandle) == nullptr || !L.running.load(); });
    --L.waiters;
    scheduled = find_callback(L, hHandle) != nullptr;
  }
  return scheduled ? HDboolean{HD_TRUE} : HDboolean{HD_FALSE};
}

}  // extern "C"
