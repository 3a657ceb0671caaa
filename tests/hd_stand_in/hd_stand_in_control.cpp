// hd_stand_in_control.cpp - the hd_stand_in_* test control API.
#include <algorithm>
#include <cmath>
#include <ctime>
#include <new>

#include "hd_stand_in_state.h"

using namespace hdsi;

extern "C" {

int hd_stand_in_reset(void) {
  if (tl_on_servo) return -1;
  Lib& L = lib();
  stop_scheduler_internal();
  clear_callbacks();
  {
    std::lock_guard<std::mutex> lock(L.err_mu);
    L.err_count = 0;
  }
  L.initialized.store(false);
  L.current.store(HD_INVALID_HANDLE);
  L.force_output.store(false);
  L.clamping.store(false);
  L.ramping.store(false);
  L.software_force_limit.store(false);
  L.one_frame_limit.store(false);
  L.force_output_at_init.store(false);
  L.velocity_limit.store(0.0);
  L.impulse_limit.store(0.0);
  L.ramping_rate.store(0.0);
  L.status_light.store(0);
  L.cal_state.store(HD_CALIBRATION_OK);
  L.cal_styles.store(HD_CALIBRATION_AUTO | HD_CALIBRATION_INKWELL);
  L.fail_init.store(HD_SUCCESS);
  L.fail_init_fault.store(0);
  L.link_lost.store(false);
  L.strict_one_frame.store(false);
  L.buttons.store(0);
  L.docked.store(false);
  L.docked_reads_one.store(false);
  L.clock_offset_s.store(1600.0);
  L.rate_hz.store(1000);
  L.instantaneous_rate.store(0.0);
  {
    std::lock_guard<std::mutex> lock(L.state_mu);
    L.device_name = kDefaultDeviceName;
    L.path_t.clear();
    L.path_xyz.clear();
    ++L.path_epoch;
    L.wave_axis = 0;
    L.wave_amp_mm = 0.0;
    L.wave_half = 0;
    ++L.wave_epoch;
    L.faults.fill(Fault{});
  }
  {
    std::lock_guard<std::mutex> lock(L.log_mu);
    L.published = FrameView{};
  }
  for (auto& v : L.violations) v.store(0);
  L.ticks.store(0);
  L.servo = Servo{};  // the servo thread is joined
  return 0;
}

int hd_stand_in_configure_log(size_t capacity) {
  Lib& L = lib();
  if (capacity == 0 || L.running.load()) return -1;
  try {
    std::vector<hd_stand_in_frame_record> fresh(capacity);
    std::lock_guard<std::mutex> lock(L.log_mu);
    L.ring.swap(fresh);
  } catch (const std::bad_alloc&) {
    return -1;
  }
  return 0;
}

void hd_stand_in_set_device_name(const char* name) {
  Lib& L = lib();
  try {
    std::string fresh = name != nullptr ? name : kDefaultDeviceName;
    std::lock_guard<std::mutex> lock(L.state_mu);
    L.device_name.swap(fresh);
  } catch (const std::bad_alloc&) {
  }
}

void hd_stand_in_set_clock_offset(double seconds) {
  if (std::isfinite(seconds)) lib().clock_offset_s.store(seconds);
}

double hd_stand_in_device_time(void) { return device_time_s(mono_ns()); }

void hd_stand_in_set_force_output_at_init(int enabled) { lib().force_output_at_init.store(enabled != 0); }

void hd_stand_in_set_inkwell_polarity(int docked_reads_one) {
  lib().docked_reads_one.store(docked_reads_one != 0);
}

void hd_stand_in_set_strict_one_frame(int on) { lib().strict_one_frame.store(on != 0); }

int hd_stand_in_set_path(const double* t_s, const double* xyz_mm, size_t n) {
  Lib& L = lib();
  std::vector<double> t;
  std::vector<double> xyz;
  if (n > 0) {
    if (t_s == nullptr || xyz_mm == nullptr || n > (size_t{1} << 26)) return -1;
    try {
      t.assign(t_s, t_s + n);
      xyz.assign(xyz_mm, xyz_mm + 3 * n);
    } catch (const std::bad_alloc&) {
      return -1;
    }
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t[i]) || (i > 0 && t[i] < t[i - 1])) return -1;
    }
  }
  {
    std::lock_guard<std::mutex> lock(L.state_mu);
    L.path_t.swap(t);
    L.path_xyz.swap(xyz);
    ++L.path_epoch;
  }
  return 0;  // the old vectors are freed here, off the servo thread
}

void hd_stand_in_set_square_wave(int axis, double amplitude_mm, int half_period_ticks) {
  Lib& L = lib();
  std::lock_guard<std::mutex> lock(L.state_mu);
  const bool on = axis >= 0 && axis < 3 && half_period_ticks > 0 && std::isfinite(amplitude_mm);
  L.wave_axis = on ? axis : 0;
  L.wave_amp_mm = on ? amplitude_mm : 0.0;
  L.wave_half = on ? half_period_ticks : 0;
  ++L.wave_epoch;
}

void hd_stand_in_set_docked(int docked) { lib().docked.store(docked != 0); }

void hd_stand_in_set_buttons(int bits) { lib().buttons.store(bits); }

void hd_stand_in_set_calibration(unsigned int state, int styles) {
  Lib& L = lib();
  if (state == HD_CALIBRATION_OK || state == HD_CALIBRATION_NEEDS_UPDATE ||
      state == HD_CALIBRATION_NEEDS_MANUAL_INPUT) {
    L.cal_state.store(state);
  }
  if (styles >= 0) {
    L.cal_styles.store(styles &
                       (HD_CALIBRATION_ENCODER_RESET | HD_CALIBRATION_AUTO | HD_CALIBRATION_INKWELL));
  }
}

int hd_stand_in_inject(int fault_kind, long tick, double value) {
  Lib& L = lib();
  switch (fault_kind) {
    case HD_STAND_IN_FAULT_INIT_FAILURE:
    case HD_STAND_IN_FAULT_INVALID_LICENSE:
      L.fail_init_fault.store(fault_kind);
      L.fail_init.store(fault_kind == HD_STAND_IN_FAULT_INIT_FAILURE ? HD_COMM_CONFIG_ERROR
                                                                     : HD_INVALID_LICENSE);
      return 0;
    case HD_STAND_IN_FAULT_LINK_LOST:
    case HD_STAND_IN_FAULT_FORCE_LIMIT:
    case HD_STAND_IN_FAULT_SCHEDULER_FULL:
    case HD_STAND_IN_FAULT_SLOW_FRAME:
    case HD_STAND_IN_FAULT_LINK_RESTORED:
      break;
    default:
      return -1;
  }
  if (!std::isfinite(value)) return -1;
  if (fault_kind == HD_STAND_IN_FAULT_SLOW_FRAME && (value < 0.0 || value > 10000.0)) return -1;
  std::lock_guard<std::mutex> lock(L.state_mu);
  for (Fault& f : L.faults) {
    if (f.used) continue;
    const int count = value >= 1.0 ? static_cast<int>(std::min(value, 1e6)) : 1;
    f = Fault{true, fault_kind, tick < 0 ? 0 : tick, value, count};
    return 0;
  }
  return -1;
}

void hd_stand_in_fail_init(unsigned int code) {
  Lib& L = lib();
  L.fail_init_fault.store(code == HD_COMM_CONFIG_ERROR ? HD_STAND_IN_FAULT_INIT_FAILURE
                          : code == HD_INVALID_LICENSE ? HD_STAND_IN_FAULT_INVALID_LICENSE
                                                       : 0);
  L.fail_init.store(code);
}

size_t hd_stand_in_frame_count(void) {
  return static_cast<size_t>(lib().ticks.load(std::memory_order_acquire));
}

size_t hd_stand_in_frame_first(void) {
  Lib& L = lib();
  const size_t count = hd_stand_in_frame_count();
  std::lock_guard<std::mutex> lock(L.log_mu);
  // The servo may already have written tick `count` over the slot of tick
  // count - size, so that one is not counted as held.
  return count + 1 > L.ring.size() ? count + 1 - L.ring.size() : 0;
}

int hd_stand_in_frame(size_t i, struct hd_stand_in_frame_record* out) {
  Lib& L = lib();
  if (out == nullptr) return 0;
  std::lock_guard<std::mutex> lock(L.log_mu);
  // Read the count under the lock: a tick's record is written before the
  // tick counter moves past it, and the servo cannot overwrite it meanwhile.
  const size_t count = static_cast<size_t>(L.ticks.load(std::memory_order_acquire));
  if (L.ring.empty() || i >= count || count - i > L.ring.size()) return 0;
  const hd_stand_in_frame_record& rec = L.ring[i % L.ring.size()];
  if (rec.tick < 0 || static_cast<size_t>(rec.tick) != i) return 0;  // already overwritten
  *out = rec;
  return 1;
}

long hd_stand_in_violations(void) {
  long total = 0;
  for (const auto& v : lib().violations) total += v.load();
  return total;
}

long hd_stand_in_violation_count(int kind) {
  if (kind <= 0 || kind >= kViolationKinds) return 0;
  return lib().violations[static_cast<size_t>(kind)].load();
}

long hd_stand_in_ticks(void) { return lib().ticks.load(std::memory_order_acquire); }

int hd_stand_in_wait_ticks(long n, double timeout_s) {
  const std::int64_t deadline = mono_ns() + static_cast<std::int64_t>(std::max(0.0, timeout_s) * 1e9);
  while (hd_stand_in_ticks() < n) {
    if (mono_ns() >= deadline) return 0;
    const timespec pause{0, 200000};
    nanosleep(&pause, nullptr);
  }
  return 1;
}

int hd_stand_in_scheduler_running(void) { return lib().running.load() ? 1 : 0; }

int hd_stand_in_scheduled_count(void) { return scheduled_count(); }

int hd_stand_in_device_initialized(void) { return lib().initialized.load() ? 1 : 0; }

int hd_stand_in_link_lost(void) { return lib().link_lost.load() ? 1 : 0; }

int hd_stand_in_error_depth(void) {
  Lib& L = lib();
  std::lock_guard<std::mutex> lock(L.err_mu);
  return L.err_count;
}

}  // extern "C"
