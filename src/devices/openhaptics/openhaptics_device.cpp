#include "devices/openhaptics/openhaptics_device.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "devices/openhaptics/hd_conversions.hpp"
#include "devices/openhaptics/hd_errors.hpp"

namespace calligraphy::openhaptics {
namespace {

double monotonic_seconds() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void throw_if_error(const HdLibrary& library, std::string_view context) {
  const hd::HDErrorInfo error = library.get_error();
  if (error.errorCode != hd::HD_SUCCESS) throw_hd_error(error, context);
}

}  // namespace

OpenHapticsDevice::OpenHapticsDevice(std::string configuration_name, double watchdog_timeout_s)
    : configuration_name_(std::move(configuration_name)), watchdog_timeout_s_(watchdog_timeout_s) {
  if (!(watchdog_timeout_s > 0.0)) throw InvalidArgument("OpenHapticsDevice: watchdog timeout must be > 0 s");
  info_.model = "OpenHaptics device (not opened)";
  info_.manufacturer = "unknown";
}

OpenHapticsDevice::~OpenHapticsDevice() { close(); }

void OpenHapticsDevice::read_info() {
  double max_force = 0, continuous = 0, stiffness = 0, damping = 0;
  std::array<double, 6> usable{};
  library_->get_doublev(hd::HD_NOMINAL_MAX_FORCE, &max_force);
  library_->get_doublev(hd::HD_NOMINAL_MAX_CONTINUOUS_FORCE, &continuous);
  library_->get_doublev(hd::HD_NOMINAL_MAX_STIFFNESS, &stiffness);
  library_->get_doublev(hd::HD_NOMINAL_MAX_DAMPING, &damping);
  library_->get_doublev(hd::HD_USABLE_WORKSPACE_DIMENSIONS, usable.data());
  info_ = info_from_hd_nominals(library_->get_string(hd::HD_DEVICE_MODEL_TYPE),
                                library_->get_string(hd::HD_DEVICE_VENDOR), max_force, continuous, stiffness,
                                damping, usable);
  throw_if_error(*library_, "reading the device's nominal limits");
}

void OpenHapticsDevice::open() {
  if (open_) return;
  library_ = HdLibrary::load();  // DeviceNotFound "OpenHaptics not found ..."
  spdlog::warn(
      "OpenHaptics: using {}; this backend was never run against a real libHD (none on the build machine)",
      library_->path);
  handle_ = library_->init_device(configuration_name_.empty() ? nullptr : configuration_name_.c_str());
  if (const hd::HDErrorInfo error = library_->get_error(); error.errorCode != hd::HD_SUCCESS) {
    handle_ = hd::HD_INVALID_HANDLE;
    library_.reset();
    throw DeviceNotFound(std::string("OpenHaptics: hdInitDevice(") +
                         (configuration_name_.empty() ? "default device" : configuration_name_) +
                         ") failed: " + hd_error_name(error.errorCode));
  }
  try {
    read_info();
    library_->enable(hd::HD_FORCE_OUTPUT);  // forces stay zero until enable_forces(true)
    scheduler_error_.store(hd::HD_SUCCESS);
    watchdog_tripped_.store(false);
    servo_callback_ = library_->schedule_asynchronous(&OpenHapticsDevice::servo_tick, this,
                                                      hd::HD_DEFAULT_SCHEDULER_PRIORITY);
    library_->start_scheduler();
    throw_if_error(*library_, "starting the scheduler");
    open_ = true;
    library_->schedule_synchronous(&OpenHapticsDevice::calibration_check, this,
                                   hd::HD_DEFAULT_SCHEDULER_PRIORITY);
    calibrated_.store(calibration_result_ == hd::HD_CALIBRATION_OK);
  } catch (...) {
    open_ = true;  // let close() undo what was done
    close();
    throw;
  }
  spdlog::info("OpenHaptics: opened {} ({}), max force {} N, {}", info_.model, info_.manufacturer,
               info_.max_force_n, is_calibrated() ? "calibrated" : "needs calibrate()");
}

void OpenHapticsDevice::close() noexcept {
  if (!open_ || !library_) {
    open_ = false;
    return;
  }
  if (const hd::HDerror error = scheduler_error_.load(); error != hd::HD_SUCCESS) {
    try {  // the servo path kept only the code; it is worded here, off the servo thread
      spdlog::warn("OpenHaptics: the scheduler reported {} ({}) during the run", hd_error_name(error),
                   device_fault_name(hd_servo_fault(error)));
    } catch (...) {
      // Logging must not turn close() into a throwing call.
    }
  }
  forces_enabled_.store(false);
  library_->stop_scheduler();
  if (servo_callback_ != 0) library_->unschedule(servo_callback_);
  servo_callback_ = 0;
  if (handle_ != hd::HD_INVALID_HANDLE) library_->disable_device(handle_);
  handle_ = hd::HD_INVALID_HANDLE;
  library_.reset();
  open_ = false;
}

hd::HDCallbackCode OpenHapticsDevice::calibration_check(void* self) noexcept {
  auto* device = static_cast<OpenHapticsDevice*>(self);
  device->calibration_result_ = device->library_->check_calibration();
  return hd::HD_CALLBACK_DONE;
}

void OpenHapticsDevice::calibrate() {
  if (!open_) throw DeviceError("OpenHaptics: calibrate() on a device that is not open");
  library_->schedule_synchronous(&OpenHapticsDevice::calibration_check, this,
                                 hd::HD_DEFAULT_SCHEDULER_PRIORITY);
  if (calibration_result_ == hd::HD_CALIBRATION_NEEDS_UPDATE) {
    hd::HDint styles = 0;
    library_->get_integerv(hd::HD_CALIBRATION_STYLE, &styles);
    // Prefer the styles that need nobody's help, as the OpenHaptics examples do.
    const hd::HDint style = (styles & hd::HD_CALIBRATION_AUTO) != 0 ? hd::HD_CALIBRATION_AUTO
                            : (styles & hd::HD_CALIBRATION_ENCODER_RESET) != 0
                                ? hd::HD_CALIBRATION_ENCODER_RESET
                                : hd::HD_CALIBRATION_INKWELL;
    library_->update_calibration(style);
    throw_if_error(*library_, "hdUpdateCalibration");
    library_->schedule_synchronous(&OpenHapticsDevice::calibration_check, this,
                                   hd::HD_DEFAULT_SCHEDULER_PRIORITY);
  }
  if (calibration_result_ == hd::HD_CALIBRATION_NEEDS_MANUAL_INPUT) {
    calibrated_.store(false);
    throw CalibrationNeeded(
        "OpenHaptics " + info_.model +
        ": calibration needs manual input (put the stylus in the inkwell), then calibrate()");
  }
  calibrated_.store(calibration_result_ == hd::HD_CALIBRATION_OK);
  if (!is_calibrated())
    throw CalibrationNeeded("OpenHaptics " + info_.model + ": calibration did not complete");
}

void OpenHapticsDevice::enable_forces(bool enabled) {
  if (enabled) {
    if (!open_) throw DeviceError("OpenHaptics: enable_forces(true) on a device that is not open");
    if (!is_calibrated())
      throw CalibrationNeeded("OpenHaptics " + info_.model + ": calibrate() before forces");
    command_.store({0.0, 0.0, 0.0, monotonic_seconds()});
    watchdog_tripped_.store(false);
  }
  forces_enabled_.store(enabled, std::memory_order_release);
}

hd::HDCallbackCode OpenHapticsDevice::servo_tick(void* self) noexcept {
  auto* device = static_cast<OpenHapticsDevice*>(self);
  const HdLibrary& hd_api = *device->library_;
  const double now = monotonic_seconds();
  hd_api.begin_frame(device->handle_);
  std::array<double, 3> position_mm{}, velocity_mm_s{};
  hd::HDint buttons = 0;
  hd_api.get_doublev(hd::HD_CURRENT_POSITION, position_mm.data());
  hd_api.get_doublev(hd::HD_CURRENT_VELOCITY, velocity_mm_s.data());
  hd_api.get_integerv(hd::HD_CURRENT_BUTTONS, &buttons);

  const auto command = device->command_.load();
  Vec3 force = Vec3::Zero();
  if (device->forces_enabled_.load(std::memory_order_acquire) &&
      device->scheduler_error_.load(std::memory_order_relaxed) == hd::HD_SUCCESS) {
    if (now - command[3] > device->watchdog_timeout_s_) {
      device->watchdog_tripped_.store(true, std::memory_order_release);
      device->forces_enabled_.store(false, std::memory_order_release);
    } else {
      force = Vec3(command[0], command[1], command[2]);
    }
  }
  const auto hd_force = device_force_to_hd(force);
  hd_api.set_doublev(hd::HD_CURRENT_FORCE, hd_force.data());
  hd_api.end_frame(device->handle_);

  const hd::HDErrorInfo error = hd_api.get_error();
  if (error.errorCode != hd::HD_SUCCESS) {
    hd::HDerror expected = hd::HD_SUCCESS;
    device->scheduler_error_.compare_exchange_strong(expected, error.errorCode);
    device->forces_enabled_.store(false, std::memory_order_release);
  }
  const Vec3 position = hd_mm_to_device_m(position_mm);
  const Vec3 velocity = hd_mm_to_device_m(velocity_mm_s);
  device->state_.store({position.x(), position.y(), position.z(), velocity.x(), velocity.y(), velocity.z(),
                        static_cast<double>(buttons), now});
  return hd::HD_CALLBACK_CONTINUE;
}

// Servo path: codes, no exception, allocation or string (the HD code is kept in scheduler_error_).
DeviceFault OpenHapticsDevice::read_state(DeviceState& state) noexcept {
  if (!open_) return DeviceFault::not_open;
  if (const hd::HDerror error = scheduler_error_.load(std::memory_order_relaxed); error != hd::HD_SUCCESS) {
    forces_enabled_.store(false);
    return hd_servo_fault(error);
  }
  if (watchdog_tripped_.exchange(false)) return DeviceFault::watchdog;
  const auto values = state_.load();
  state.position_m = Vec3(values[0], values[1], values[2]);
  state.velocity_m_s = Vec3(values[3], values[4], values[5]);
  state.buttons = static_cast<std::uint32_t>(values[6]);
  state.time_s = values[7];
  return DeviceFault::none;
}

DeviceFault OpenHapticsDevice::write_force(const Vec3& force_n) noexcept {
  if (!open_) return DeviceFault::not_open;
  const double now = monotonic_seconds();
  if (!force_n.allFinite()) {
    forces_enabled_.store(false, std::memory_order_release);
    command_.store({0.0, 0.0, 0.0, now});
    return DeviceFault::non_finite_force;
  }
  const Vec3 limited = clamp_force_magnitude(force_n, info_.max_force_n);
  command_.store({limited.x(), limited.y(), limited.z(), now});
  return DeviceFault::none;
}

}  // namespace calligraphy::openhaptics
