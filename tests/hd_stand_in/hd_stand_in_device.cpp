// hd_stand_in_device.cpp - HDAPI device routines of the stand-in libHD.so:
// error stack, device handles, haptic frames, parameter get/set,
// capabilities and calibration.
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <type_traits>

#include "hd_stand_in_state.h"

namespace hdsi {

thread_local bool tl_on_servo = false;

Lib::Lib() { ring.resize(kDefaultLogCapacity); }

Lib& lib() {
  // Heap-allocated so that it outlives every static destructor run by
  // exit(); freed by hd_stand_in_unload() below, which the loader runs at
  // dlclose() or after the atexit handlers, once nothing can call in.
  static Lib* const instance = new Lib();
  return *instance;
}

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

double device_time_s(std::int64_t mono) {
  return static_cast<double>(mono) * 1e-9 + lib().clock_offset_s.load(std::memory_order_relaxed);
}

void push_error(HDerror code, int internal) {
  Lib& L = lib();
  const HDErrorInfo info{code, internal, L.current.load(std::memory_order_relaxed)};
  {
    std::lock_guard<std::mutex> lock(L.err_mu);
    if (L.err_count == kErrorStackCap) {
      // Full: forget the oldest entry so the most recent ones survive.
      for (int i = 1; i < kErrorStackCap; ++i)
        L.errors[static_cast<std::size_t>(i - 1)] = L.errors[static_cast<std::size_t>(i)];
      --L.err_count;
    }
    L.errors[static_cast<std::size_t>(L.err_count++)] = info;
  }
  if (tl_on_servo) {
    Servo& S = L.servo;
    if (S.error_count++ == 0) S.first_error = code;
  }
}

void violation(int kind, HDerror code) {
  Lib& L = lib();
  if (kind > 0 && kind < kViolationKinds)
    L.violations[static_cast<std::size_t>(kind)].fetch_add(1, std::memory_order_relaxed);
  push_error(code, HD_STAND_IN_INTERNAL_VIOLATION_BASE + kind);
}

bool require_device() {
  Lib& L = lib();
  if (!L.initialized.load(std::memory_order_acquire) ||
      L.current.load(std::memory_order_relaxed) != kDeviceHandle) {
    push_error(HD_BAD_HANDLE, HD_STAND_IN_INTERNAL_API);
    return false;
  }
  return true;
}

namespace {

enum class Kind { Float, Int, Bool };
struct Value {
  Kind kind = Kind::Float;
  int n = 0;
  std::array<double, 16> v{};
};

bool is_frame_param(HDenum p) {
  switch (p) {
    case HD_CURRENT_BUTTONS:
    case HD_CURRENT_INKWELL_SWITCH:
    case HD_CURRENT_POSITION:
    case HD_CURRENT_VELOCITY:
    case HD_CURRENT_TRANSFORM:
    case HD_LAST_BUTTONS:
    case HD_LAST_INKWELL_SWITCH:
    case HD_LAST_POSITION:
    case HD_LAST_VELOCITY:
    case HD_LAST_TRANSFORM:
    case HD_CURRENT_FORCE:
      return true;
    default:
      return false;
  }
}

void put3(Value& out, const Vec3& a) {
  out.kind = Kind::Float;
  out.n = 3;
  for (std::size_t i = 0; i < 3; ++i) out.v[i] = a[i];
}

// Column-major 4x4 (OpenGL / hduMatrix layout): identity rotation, translation
// in elements 12..14. Orientation of the stylus is not modelled.
void put_transform(Value& out, const Vec3& p) {
  out.kind = Kind::Float;
  out.n = 16;
  out.v.fill(0.0);
  out.v[0] = out.v[5] = out.v[10] = out.v[15] = 1.0;
  out.v[12] = p[0];
  out.v[13] = p[1];
  out.v[14] = p[2];
}

void put1(Value& out, Kind k, double x) {
  out.kind = k;
  out.n = 1;
  out.v[0] = x;
}

void fill_frame_param(HDenum p, const FrameView& f, Value& out) {
  switch (p) {
    case HD_CURRENT_BUTTONS:
      put1(out, Kind::Int, f.buttons);
      break;
    case HD_LAST_BUTTONS:
      put1(out, Kind::Int, f.last_buttons);
      break;
    case HD_CURRENT_INKWELL_SWITCH:
      put1(out, Kind::Bool, f.ink);
      break;
    case HD_LAST_INKWELL_SWITCH:
      put1(out, Kind::Bool, f.last_ink);
      break;
    case HD_CURRENT_POSITION:
      put3(out, f.pos);
      break;
    case HD_LAST_POSITION:
      put3(out, f.last_pos);
      break;
    case HD_CURRENT_VELOCITY:
      put3(out, f.vel);
      break;
    case HD_LAST_VELOCITY:
      put3(out, f.last_vel);
      break;
    case HD_CURRENT_TRANSFORM:
      put_transform(out, f.pos);
      break;
    case HD_LAST_TRANSFORM:
      put_transform(out, f.last_pos);
      break;
    case HD_CURRENT_FORCE:
      put3(out, f.force);
      break;
    default:
      break;
  }
}

// Reads one parameter. Pushes the error and returns false when nothing may be
// written to the caller's array.
bool read_param(HDenum p, Value& out) {
  Lib& L = lib();
  if (is_frame_param(p)) {
    if (!require_device()) return false;
    if (!tl_on_servo) {
      // Off the servo thread: flag it, then answer like HDAPI does
      // outside a frame, with the last frame's state.
      violation(HD_STAND_IN_VIOLATION_WRONG_THREAD, HD_INVALID_OPERATION);
      FrameView snapshot;
      {
        std::lock_guard<std::mutex> lock(L.log_mu);
        snapshot = L.published;
      }
      fill_frame_param(p, snapshot, out);
      return true;
    }
    Servo& S = L.servo;
    if (!S.frame_open) {
      violation(HD_STAND_IN_VIOLATION_READ_OUTSIDE_FRAME, HD_INVALID_OPERATION);
    } else if (p == HD_CURRENT_POSITION) {
      S.position_read = true;
    }
    fill_frame_param(p, S.view, out);
    return true;
  }
  if (p == HD_VERSION) {
    push_error(HD_INVALID_INPUT_TYPE, HD_STAND_IN_INTERNAL_API);  // a string: hdGetString
    return false;
  }
  if (!require_device()) return false;
  switch (p) {
    case HD_NOMINAL_MAX_FORCE:
      put1(out, Kind::Float, kMaxForceN);
      return true;
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE:
      put1(out, Kind::Float, kMaxContinuousForceN);
      return true;
    case HD_NOMINAL_MAX_STIFFNESS:
      put1(out, Kind::Float, kMaxStiffnessNPerMm);
      return true;
    case HD_NOMINAL_MAX_DAMPING:
      put1(out, Kind::Float, kMaxDampingNsPerMm);
      return true;
    case HD_USABLE_WORKSPACE_DIMENSIONS:
    case HD_MAX_WORKSPACE_DIMENSIONS:
      out.kind = Kind::Float;
      out.n = 6;
      for (std::size_t i = 0; i < 6; ++i) out.v[i] = kUsableWorkspaceMm[i];
      return true;
    case HD_INPUT_DOF:
      put1(out, Kind::Int, 6);
      return true;
    case HD_OUTPUT_DOF:
      put1(out, Kind::Int, 3);
      return true;
    case HD_CALIBRATION_STYLE:
      put1(out, Kind::Int, L.cal_styles.load());
      return true;
    case HD_UPDATE_RATE:
      put1(out, Kind::Int, static_cast<double>(L.rate_hz.load()));
      return true;
    case HD_INSTANTANEOUS_UPDATE_RATE:
      put1(out, Kind::Int, std::round(L.instantaneous_rate.load()));
      return true;
    case HD_SOFTWARE_VELOCITY_LIMIT:
      put1(out, Kind::Float, L.velocity_limit.load());
      return true;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT:
      put1(out, Kind::Float, L.impulse_limit.load());
      return true;
    case HD_FORCE_RAMPING_RATE:
      put1(out, Kind::Float, L.ramping_rate.load());
      return true;
    case HD_USER_STATUS_LIGHT:
      put1(out, Kind::Int, L.status_light.load());
      return true;
    default:
      push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
      return false;
  }
}

template <class T>
bool accepts(Kind k) {
  if constexpr (std::is_same_v<T, HDdouble> || std::is_same_v<T, HDfloat>) {
    return k == Kind::Float || k == Kind::Int;
  } else if constexpr (std::is_same_v<T, HDboolean>) {
    return k == Kind::Bool;
  } else {
    return k == Kind::Int || k == Kind::Bool;
  }
}

template <class T>
void get_typed(HDenum p, T* params) {
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  Value v;
  if (!read_param(p, v)) return;
  if (!accepts<T>(v.kind)) {
    push_error(HD_INVALID_INPUT_TYPE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  for (int i = 0; i < v.n; ++i) {
    const double x = v.v[static_cast<std::size_t>(i)];
    if constexpr (std::is_same_v<T, HDboolean>) {
      params[i] = x != 0.0 ? HDboolean{1} : HDboolean{0};
    } else {
      params[i] = static_cast<T>(x);
    }
  }
}

void set_force(const Vec3& f) {
  Lib& L = lib();
  if (!require_device()) return;
  if (!tl_on_servo) {
    violation(HD_STAND_IN_VIOLATION_WRONG_THREAD, HD_INVALID_OPERATION);
    return;
  }
  Servo& S = L.servo;
  if (!S.frame_open) {
    violation(HD_STAND_IN_VIOLATION_SET_OUTSIDE_FRAME, HD_INVALID_OPERATION);
    return;
  }
  if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  S.view.force = f;
  S.force_set = true;
}

template <class T>
void set_typed(HDenum p, const T* params) {
  Lib& L = lib();
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  constexpr bool is_float = std::is_same_v<T, HDdouble> || std::is_same_v<T, HDfloat>;
  constexpr bool is_int = std::is_same_v<T, HDint> || std::is_same_v<T, HDlong>;
  switch (p) {
    case HD_CURRENT_FORCE:
      if constexpr (!is_float) {
        push_error(HD_INVALID_INPUT_TYPE, HD_STAND_IN_INTERNAL_API);
      } else {
        set_force(
            {static_cast<double>(params[0]), static_cast<double>(params[1]), static_cast<double>(params[2])});
      }
      return;
    case HD_SOFTWARE_VELOCITY_LIMIT:
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT:
    case HD_FORCE_RAMPING_RATE: {
      if constexpr (!is_float) {
        push_error(HD_INVALID_INPUT_TYPE, HD_STAND_IN_INTERNAL_API);
      } else {
        if (!require_device()) return;
        const double x = static_cast<double>(params[0]);
        if (!std::isfinite(x) || x < 0.0) {
          push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
          return;
        }
        (p == HD_SOFTWARE_VELOCITY_LIMIT        ? L.velocity_limit
         : p == HD_SOFTWARE_FORCE_IMPULSE_LIMIT ? L.impulse_limit
                                                : L.ramping_rate)
            .store(x);
      }
      return;
    }
    case HD_USER_STATUS_LIGHT:
      if constexpr (!is_int) {
        push_error(HD_INVALID_INPUT_TYPE, HD_STAND_IN_INTERNAL_API);
      } else {
        if (!require_device()) return;
        L.status_light.store(static_cast<int>(params[0]));
      }
      return;
    default:
      // Read-only or unknown parameter.
      push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
      return;
  }
}

std::atomic<bool>* capability(HDenum cap) {
  Lib& L = lib();
  switch (cap) {
    case HD_FORCE_OUTPUT:
      return &L.force_output;
    case HD_MAX_FORCE_CLAMPING:
      return &L.clamping;
    case HD_FORCE_RAMPING:
      return &L.ramping;
    case HD_SOFTWARE_FORCE_LIMIT:
      return &L.software_force_limit;
    case HD_ONE_FRAME_LIMIT:
      return &L.one_frame_limit;
    default:
      return nullptr;
  }
}

void apply_force_at_end_frame() {
  Lib& L = lib();
  Servo& S = L.servo;
  S.output = false;
  S.out = {0.0, 0.0, 0.0};
  if (S.force_limit_pending) {
    S.force_limit_pending = false;
    L.force_output.store(false);
    push_error(HD_EXCEEDED_MAX_FORCE, HD_STAND_IN_INTERNAL_FAULT_BASE + HD_STAND_IN_FAULT_FORCE_LIMIT);
    return;
  }
  if (L.link_lost.load(std::memory_order_relaxed) || !L.force_output.load()) return;
  Vec3 f = S.view.force;
  const double mag = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (mag > kMaxForceN) {
    if (L.clamping.load()) {
      for (double& c : f) c *= kMaxForceN / mag;
    } else {
      // The device refuses the frame and turns its motors off.
      L.force_output.store(false);
      push_error(HD_EXCEEDED_MAX_FORCE, HD_STAND_IN_INTERNAL_FORCE_MODEL);
      return;
    }
  }
  S.output = true;
  S.out = f;
}

}  // namespace
}  // namespace hdsi

using namespace hdsi;

extern "C" {

// ---- errors ----------------------------------------------------------------

HDErrorInfo hdGetError(void) {
  Lib& L = lib();
  std::lock_guard<std::mutex> lock(L.err_mu);
  if (L.err_count == 0) return HDErrorInfo{HD_SUCCESS, 0, L.current.load(std::memory_order_relaxed)};
  return L.errors[static_cast<std::size_t>(--L.err_count)];
}

HDstring hdGetErrorString(HDerror code) {
  switch (code) {
    case HD_SUCCESS:
      return "No error";
    case HD_INVALID_ENUM:
      return "Invalid enumerant";
    case HD_INVALID_VALUE:
      return "Invalid value";
    case HD_INVALID_OPERATION:
      return "Invalid operation";
    case HD_INVALID_INPUT_TYPE:
      return "Invalid input type";
    case HD_BAD_HANDLE:
      return "Bad device handle";
    case HD_WARM_MOTORS:
      return "Motors are warm";
    case HD_EXCEEDED_MAX_FORCE:
      return "Exceeded maximum force";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE:
      return "Exceeded maximum force impulse";
    case HD_EXCEEDED_MAX_VELOCITY:
      return "Exceeded maximum velocity";
    case HD_FORCE_ERROR:
      return "Force error";
    case HD_DEVICE_FAULT:
      return "Device fault";
    case HD_DEVICE_ALREADY_INITIATED:
      return "Device already initiated";
    case HD_COMM_ERROR:
      return "Communication error";
    case HD_COMM_CONFIG_ERROR:
      return "Communication configuration error";
    case HD_TIMER_ERROR:
      return "Timer error";
    case HD_ILLEGAL_BEGIN:
      return "Illegal begin frame";
    case HD_ILLEGAL_END:
      return "Illegal end frame";
    case HD_FRAME_ERROR:
      return "Frame error";
    case HD_INVALID_PRIORITY:
      return "Invalid scheduler priority";
    case HD_SCHEDULER_FULL:
      return "Scheduler full";
    case HD_INVALID_LICENSE:
      return "Invalid license";
    default:
      return "Unknown error";
  }
}

// ---- devices ---------------------------------------------------------------

HHD hdInitDevice(HDstring pConfigName) {
  Lib& L = lib();
  switch (environment_faults().init) {  // a hostile driver (HD_STAND_IN_INIT)
    case InitMisbehaviour::crash:
      std::raise(SIGSEGV);
      break;
    case InitMisbehaviour::hang:
      for (;;) ::pause();
    case InitMisbehaviour::exit:
      std::exit(environment_faults().exit_status);
    case InitMisbehaviour::none:
      break;
  }
  const HDerror fail = L.fail_init.load();
  if (fail != HD_SUCCESS) {
    const int fault = L.fail_init_fault.load();
    push_error(fail, fault != 0 ? HD_STAND_IN_INTERNAL_FAULT_BASE + fault : HD_STAND_IN_INTERNAL_API);
    return HD_INVALID_HANDLE;
  }
  bool known = pConfigName == nullptr || std::strcmp(pConfigName, kDefaultDeviceName) == 0;
  if (!known) {
    std::lock_guard<std::mutex> lock(L.state_mu);
    known = L.device_name == pConfigName;
  }
  if (!known) {
    push_error(HD_COMM_CONFIG_ERROR, HD_STAND_IN_INTERNAL_API);
    return HD_INVALID_HANDLE;
  }
  if (L.initialized.exchange(true)) {
    push_error(HD_DEVICE_ALREADY_INITIATED, HD_STAND_IN_INTERNAL_API);
    return HD_INVALID_HANDLE;
  }
  L.force_output.store(L.force_output_at_init.load());
  L.clamping.store(false);
  L.ramping.store(false);
  L.software_force_limit.store(false);
  L.one_frame_limit.store(false);
  L.current.store(kDeviceHandle);
  return kDeviceHandle;
}

void hdDisableDevice(HHD hHD) {
  Lib& L = lib();
  if (hHD != kDeviceHandle || !L.initialized.load()) {
    push_error(HD_BAD_HANDLE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  L.force_output.store(false);
  L.initialized.store(false);
  HHD expected = kDeviceHandle;
  L.current.compare_exchange_strong(expected, HD_INVALID_HANDLE);
}

void hdMakeCurrentDevice(HHD hHD) {
  Lib& L = lib();
  if (hHD != kDeviceHandle || !L.initialized.load()) {
    push_error(HD_BAD_HANDLE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  L.current.store(hHD);
}

HHD hdGetCurrentDevice(void) { return lib().current.load(); }

// ---- frames ----------------------------------------------------------------

void hdBeginFrame(HHD hHD) {
  Lib& L = lib();
  if (!tl_on_servo) {
    violation(HD_STAND_IN_VIOLATION_WRONG_THREAD, HD_ILLEGAL_BEGIN);
    return;
  }
  if (hHD != kDeviceHandle || !L.initialized.load()) {
    push_error(HD_BAD_HANDLE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  Servo& S = L.servo;
  if (S.frame_open) {
    violation(HD_STAND_IN_VIOLATION_NESTED_BEGIN, HD_ILLEGAL_BEGIN);
    return;
  }
  if (S.frames_done > 0 && L.strict_one_frame.load(std::memory_order_relaxed)) {
    violation(HD_STAND_IN_VIOLATION_SECOND_FRAME_IN_TICK, HD_ILLEGAL_BEGIN);
    return;
  }
  S.frame_open = true;
  if (L.link_lost.load(std::memory_order_relaxed)) {
    push_error(HD_COMM_ERROR, HD_STAND_IN_INTERNAL_FAULT_BASE + HD_STAND_IN_FAULT_LINK_LOST);
  }
}

void hdEndFrame(HHD hHD) {
  Lib& L = lib();
  if (!tl_on_servo) {
    violation(HD_STAND_IN_VIOLATION_WRONG_THREAD, HD_ILLEGAL_END);
    return;
  }
  Servo& S = L.servo;
  if (!S.frame_open) {
    violation(HD_STAND_IN_VIOLATION_END_WITHOUT_BEGIN, HD_ILLEGAL_END);
    return;
  }
  if (hHD != kDeviceHandle) {
    push_error(HD_ILLEGAL_END, HD_STAND_IN_INTERNAL_API);  // not the device of this frame
    return;
  }
  S.frame_open = false;
  ++S.frames_done;
  apply_force_at_end_frame();
}

// ---- parameters --------------------------------------------------------------

void hdGetBooleanv(HDenum pname, HDboolean* params) { get_typed(pname, params); }
void hdGetIntegerv(HDenum pname, HDint* params) { get_typed(pname, params); }
void hdGetFloatv(HDenum pname, HDfloat* params) { get_typed(pname, params); }
void hdGetDoublev(HDenum pname, HDdouble* params) { get_typed(pname, params); }
void hdGetLongv(HDenum pname, HDlong* params) { get_typed(pname, params); }
void hdSetBooleanv(HDenum pname, const HDboolean* params) { set_typed(pname, params); }
void hdSetIntegerv(HDenum pname, const HDint* params) { set_typed(pname, params); }
void hdSetFloatv(HDenum pname, const HDfloat* params) { set_typed(pname, params); }
void hdSetDoublev(HDenum pname, const HDdouble* params) { set_typed(pname, params); }
void hdSetLongv(HDenum pname, const HDlong* params) { set_typed(pname, params); }

HDstring hdGetString(HDenum pname) {
  if (pname == HD_VERSION) return "3.4.0 (hd_stand_in)";
  switch (pname) {
    case HD_DEVICE_MODEL_TYPE:
    case HD_DEVICE_VENDOR:
    case HD_DEVICE_DRIVER_VERSION:
    case HD_DEVICE_SERIAL_NUMBER:
      break;
    default:
      push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
      return "";
  }
  if (!require_device()) return "";
  switch (pname) {
    case HD_DEVICE_MODEL_TYPE:
      return "Touch";
    case HD_DEVICE_VENDOR:
      return "3D Systems";
    case HD_DEVICE_DRIVER_VERSION:
      return "hd_stand_in";
    default:
      return "00000000000";
  }
}

// ---- capabilities ------------------------------------------------------------

void hdEnable(HDenum cap) {
  std::atomic<bool>* flag = capability(cap);
  if (flag == nullptr) {
    push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
    return;
  }
  if (!require_device()) return;
  flag->store(true);
}

void hdDisable(HDenum cap) {
  std::atomic<bool>* flag = capability(cap);
  if (flag == nullptr) {
    push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
    return;
  }
  if (!require_device()) return;
  flag->store(false);
}

HDboolean hdIsEnabled(HDenum cap) {
  std::atomic<bool>* flag = capability(cap);
  if (flag == nullptr) {
    push_error(HD_INVALID_ENUM, HD_STAND_IN_INTERNAL_API);
    return HD_FALSE;
  }
  if (!require_device()) return HD_FALSE;
  return flag->load() ? HDboolean{HD_TRUE} : HDboolean{HD_FALSE};
}

// ---- calibration ---------------------------------------------------------------

HDenum hdCheckCalibration(void) {
  if (!require_device()) return HD_CALIBRATION_OK;
  return lib().cal_state.load();
}

void hdUpdateCalibration(HDenum style) {
  Lib& L = lib();
  if (!require_device()) return;
  const bool single = style == HD_CALIBRATION_ENCODER_RESET || style == HD_CALIBRATION_AUTO ||
                      style == HD_CALIBRATION_INKWELL;
  if (!single || (L.cal_styles.load() & static_cast<int>(style)) == 0) {
    push_error(HD_INVALID_VALUE, HD_STAND_IN_INTERNAL_API);
    return;
  }
  // Inkwell calibration needs the stylus in the inkwell; otherwise nothing
  // happens (no error), as with the real arm.
  if (style == HD_CALIBRATION_INKWELL && !L.docked.load()) return;
  L.cal_state.store(HD_CALIBRATION_OK);
}

}  // extern "C"

// Stop the servo thread before the code it runs is unmapped (dlclose) or the
// process ends, then free the state.
__attribute__((destructor)) static void hd_stand_in_unload() {
  hdsi::stop_scheduler_internal();
  hdsi::clear_callbacks();
  delete &hdsi::lib();
}
