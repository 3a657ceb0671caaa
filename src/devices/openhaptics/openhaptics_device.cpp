#include "devices/openhaptics/openhaptics_device.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/core/stop_signals.hpp"
#include "core/library_log.hpp"
#include "core/rate_text.hpp"
#include "devices/openhaptics/hd_conversions.hpp"
#include "devices/openhaptics/hd_errors.hpp"

namespace calligraphy::openhaptics {
namespace {

constexpr double kDefaultSchedulerRateHz = 1000.0;  // HDAPI reference: the scheduler's default rate
// How long a call into the scheduler may wait for its callback to run: a running scheduler calls within a
// period, so seconds mean that the driver's servo thread does not run.
constexpr double kSchedulerCallTimeoutS = 5.0;

double monotonic_seconds() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void throw_if_error(const HdLibrary& library, std::string_view context) {
  const hd::HDErrorInfo error = library.get_error();
  if (error.errorCode != hd::HD_SUCCESS) throw_hd_error(error, context);
}

}  // namespace

OpenHapticsDevice::OpenHapticsDevice(std::string configuration_name, double watchdog_timeout_s,
                                     double servo_rate_hz)
    : configuration_name_(std::move(configuration_name)),
      watchdog_timeout_s_(watchdog_timeout_s),
      servo_rate_hz_(servo_rate_hz) {
  if (!(watchdog_timeout_s > 0.0)) throw InvalidArgument("OpenHapticsDevice: watchdog timeout must be > 0 s");
  if (!servo_rate_allowed(servo_rate_hz, true)) {
    throw InvalidArgument("OpenHapticsDevice: servo rate " + detail::rate_text(servo_rate_hz) +
                          " must be in " + servo_rate_range_text(true));
  }
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
  library_ = HdLibrary::load(configuration_name_);  // probed in a child process first (hd_probe.hpp)
  calligraphy::detail::library_log().warn(
      "OpenHaptics: using {}; this backend was tested against a stand-in libHD written from the public HDAPI "
      "reference (frames, scheduler, errors, calibration, faults), never against 3D Systems' libHD and an "
      "arm",
      library_->path);
  handle_ = library_->init_device(configuration_name_.empty() ? nullptr : configuration_name_.c_str());
  if (const hd::HDErrorInfo error = library_->get_error(); error.errorCode != hd::HD_SUCCESS) {
    handle_ = hd::HD_INVALID_HANDLE;
    const std::string path = library_->path;
    library_.reset();
    throw DeviceUnavailable(std::string("OpenHaptics: ") + path + " loaded, but hdInitDevice(" +
                            (configuration_name_.empty() ? "default device" : configuration_name_) +
                            ") failed with " + hd_error_name(error.errorCode) + " (internal code " +
                            std::to_string(error.internalErrorCode) +
                            "): " + hd_init_advice(error.errorCode));
  }
  try {
    read_info();
    library_->enable(hd::HD_FORCE_OUTPUT);  // forces stay zero until enable_forces(true)
    scheduler_error_.store(hd::HD_SUCCESS);
    watchdog_tripped_.store(false);
    if (library_->set_scheduler_rate != nullptr) {
      library_->set_scheduler_rate(static_cast<unsigned long>(std::lround(servo_rate_hz_)));
      throw_if_error(*library_,
                     "setting the scheduler rate to " + std::to_string(std::lround(servo_rate_hz_)) + " Hz");
    } else if (servo_rate_hz_ != kDefaultSchedulerRateHz) {
      throw DeviceError("OpenHaptics: " + library_->path +
                        " has no hdSetSchedulerRate, so its scheduler runs at 1000 Hz, not " +
                        std::to_string(std::lround(servo_rate_hz_)) + " Hz");
    }
    servo_callback_ = library_->schedule_asynchronous(&OpenHapticsDevice::servo_tick, this,
                                                      hd::HD_DEFAULT_SCHEDULER_PRIORITY);
    throw_if_error(*library_, "scheduling the servo callback");
    library_->start_scheduler();
    throw_if_error(*library_, "starting the scheduler");
    open_ = true;
    call_in_scheduler(&OpenHapticsDevice::calibration_check, "checking the calibration");
    calibrated_.store(calibration_result_ == hd::HD_CALIBRATION_OK);
  } catch (...) {
    open_ = true;  // let close() undo what was done
    close();
    throw;
  }
  calligraphy::detail::library_log().info("OpenHaptics: opened {} ({}), max force {} N, {}", info_.model,
                                          info_.manufacturer, info_.max_force_n,
                                          is_calibrated() ? "calibrated" : "needs calibrate()");
}

void OpenHapticsDevice::close() noexcept {
  if (!open_ || !library_) {
    open_ = false;
    return;
  }
  if (const hd::HDerror error = scheduler_error_.load(); error != hd::HD_SUCCESS) {
    try {  // the servo path kept only the code; it is worded here, off the servo thread
      calligraphy::detail::library_log().warn("OpenHaptics: the scheduler reported {} ({}) during the run",
                                              hd_error_name(error), device_fault_name(hd_servo_fault(error)));
    } catch (...) {
      // Logging must not turn close() into a throwing call.
    }
  }
  forces_enabled_.store(false);
  detach();
  stop_driver_bounded();
  servo_callback_ = 0;
  handle_ = hd::HD_INVALID_HANDLE;
  library_.reset();  // the library stays loaded while a stop left running still holds it
  open_ = false;
}

namespace {

// What closing hands to the thread that stops the driver: copies, never the device (which may be gone by the
// time a stuck driver returns).
struct DriverStop {
  std::shared_ptr<const HdLibrary> library;
  hd::HDSchedulerHandle servo_callback = 0;
  hd::HHD handle = hd::HD_INVALID_HANDLE;
  std::atomic<bool> unscheduled{false};  // the driver calls the device's servo callback no more
  std::atomic<bool> done{false};
};

// The servo callback first (hdUnschedule returns once it is not running), so that a driver stuck in what
// follows never calls into a device that is gone.
void stop_driver(DriverStop& stop) noexcept {
  if (stop.servo_callback != 0) stop.library->unschedule(stop.servo_callback);
  stop.unscheduled.store(true, std::memory_order_release);
  stop.library->stop_scheduler();
  if (stop.handle != hd::HD_INVALID_HANDLE) stop.library->disable_device(stop.handle);
  stop.done.store(true, std::memory_order_release);
}

}  // namespace

// hdStopScheduler waits for the driver's servo thread and hdDisableDevice for the device: a driver stuck
// there would hold close() for ever, and with it a trial's outputs, which are written once the device is
// closed. The calls run on a thread of their own, waited for at most kSchedulerCallTimeoutS; past that the
// thread and the library it holds are left to the process, and the log says so. Only hdUnschedule of the
// servo callback is waited for without a bound: until it returns the driver may call into the device.
void OpenHapticsDevice::stop_driver_bounded() noexcept {
  auto stop = std::make_shared<DriverStop>();
  stop->library = library_;
  stop->servo_callback = servo_callback_;
  stop->handle = handle_;
  try {
    std::thread([stop] { stop_driver(*stop); }).detach();
  } catch (...) {  // no thread to be had: stopped here, unbounded, as before
    stop_driver(*stop);
    return;
  }
  const double give_up = monotonic_seconds() + kSchedulerCallTimeoutS;
  while (!stop->done.load(std::memory_order_acquire) && monotonic_seconds() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (stop->done.load(std::memory_order_acquire)) return;
  const auto warn = [this](const char* what) noexcept {
    try {
      calligraphy::detail::library_log().warn("OpenHaptics: {} did not stop within {} s ({}){}",
                                              library_->path, static_cast<int>(kSchedulerCallTimeoutS), what,
                                              "; the trial's ticks are kept");
    } catch (...) {
      // Logging must not turn close() into a throwing call.
    }
  };
  if (stop->unscheduled.load(std::memory_order_acquire)) {
    warn("hdStopScheduler, hdDisableDevice: the device was left to the driver");
    return;
  }
  // The driver still holds the servo callback: the device cannot go while it may be called, so this waits.
  warn("hdUnschedule: waiting until the driver lets go of the servo callback");
  while (!stop->unscheduled.load(std::memory_order_acquire))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

namespace {

// One call of a device function in the scheduler's thread, and whether it ran.
struct SchedulerCall {
  OpenHapticsDevice* device;
  hd::SchedulerCallback function;
  std::atomic<bool> done{false};
};

hd::HDCallbackCode run_scheduler_call(void* context) noexcept {
  auto* call = static_cast<SchedulerCall*>(context);
  call->function(call->device);
  call->done.store(true, std::memory_order_release);
  return hd::HD_CALLBACK_DONE;
}

}  // namespace

// hdScheduleSynchronous would block for as long as the driver's scheduler does not run, deaf to Ctrl-C:
// the call is scheduled asynchronously instead and waited for here, bounded and polling the stop signals.
void OpenHapticsDevice::call_in_scheduler(hd::SchedulerCallback function, const char* what) {
  SchedulerCall call{this, function};
  const hd::HDSchedulerHandle handle =
      library_->schedule_asynchronous(&run_scheduler_call, &call, hd::HD_DEFAULT_SCHEDULER_PRIORITY);
  throw_if_error(*library_, std::string("scheduling a call (") + what + ")");
  const double give_up = monotonic_seconds() + kSchedulerCallTimeoutS;
  int signal = 0;
  while (!call.done.load(std::memory_order_acquire)) {
    signal = StopSignals::received();
    if (signal != 0 || monotonic_seconds() > give_up) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (call.done.load(std::memory_order_acquire)) return;
  library_->unschedule(handle);  // returns once the call is not running: `call` may go
  if (call.done.load(std::memory_order_acquire)) return;
  if (signal != 0) {
    throw DeviceError(std::string("OpenHaptics: stopped by ") + signal_name(signal) +
                      " while waiting for the HD scheduler of " + library_->path + " (" + what + ")");
  }
  throw DeviceError("OpenHaptics: the HD scheduler of " + library_->path + " ran no callback within " +
                    std::to_string(static_cast<int>(kSchedulerCallTimeoutS)) + " s (" + what +
                    "): hdStartScheduler returned, but the driver's servo loop does not run");
}

hd::HDCallbackCode OpenHapticsDevice::calibration_check(void* self) noexcept {
  auto* device = static_cast<OpenHapticsDevice*>(self);
  device->calibration_result_ = device->library_->check_calibration();
  return hd::HD_CALLBACK_DONE;
}

void OpenHapticsDevice::calibrate() {
  if (!open_) throw DeviceError("OpenHaptics: calibrate() on a device that is not open");
  call_in_scheduler(&OpenHapticsDevice::calibration_check, "checking the calibration");
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
    call_in_scheduler(&OpenHapticsDevice::calibration_check, "checking the calibration");
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
  // An error of this frame's reads (a lost link) is known before the frame function runs, so the tick
  // that reads this state also sees the fault.
  const auto note_error = [device](const hd::HDErrorInfo& error) noexcept {
    if (error.errorCode == hd::HD_SUCCESS) return;
    hd::HDerror expected = hd::HD_SUCCESS;
    device->scheduler_error_.compare_exchange_strong(expected, error.errorCode);
    device->forces_enabled_.store(false, std::memory_order_release);
  };
  note_error(hd_api.get_error());
  device->frame_state_.position_m = hd_mm_to_device_m(position_mm);
  device->frame_state_.velocity_m_s = hd_mm_to_device_m(velocity_mm_s);
  device->frame_state_.buttons = static_cast<std::uint32_t>(buttons);
  device->frame_state_.time_s = now;

  Vec3 force = Vec3::Zero();
  const bool healthy = device->forces_enabled_.load(std::memory_order_acquire) &&
                       device->scheduler_error_.load(std::memory_order_relaxed) == hd::HD_SUCCESS;
  // Device clock: the attached tick reads this frame's state and sets this frame's force.
  device->frame_busy_.store(true, std::memory_order_seq_cst);
  const FrameFunction frame = device->frame_.load(std::memory_order_seq_cst);
  if (frame != nullptr) {
    device->frame_force_set_ = false;
    device->in_frame_.store(true, std::memory_order_relaxed);
    frame(device->frame_context_.load(std::memory_order_relaxed));
    device->in_frame_.store(false, std::memory_order_relaxed);
    if (device->frame_force_set_ && device->forces_enabled_.load(std::memory_order_acquire) &&
        device->scheduler_error_.load(std::memory_order_relaxed) == hd::HD_SUCCESS) {
      force = device->frame_force_;
    }
  }
  device->frame_busy_.store(false, std::memory_order_release);
  if (frame == nullptr && healthy) {  // the latest command of another thread, within the watchdog
    const auto command = device->command_.load();
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
  note_error(hd_api.get_error());
  device->publish_frame_state();
  return hd::HD_CALLBACK_CONTINUE;
}

void OpenHapticsDevice::publish_frame_state() noexcept {
  const DeviceState& s = frame_state_;
  state_.store({s.position_m.x(), s.position_m.y(), s.position_m.z(), s.velocity_m_s.x(), s.velocity_m_s.y(),
                s.velocity_m_s.z(), static_cast<double>(s.buttons), s.time_s});
}

void OpenHapticsDevice::attach(FrameFunction frame, void* context) {
  if (!open_) throw DeviceError("OpenHaptics: attach() to a device that is not open");
  if (frame == nullptr) throw InvalidArgument("OpenHaptics: attach() needs a frame function");
  if (frame_.load() != nullptr) throw StateError("OpenHaptics: a frame function is attached already");
  frame_context_.store(context, std::memory_order_relaxed);
  frame_.store(frame, std::memory_order_seq_cst);
}

void OpenHapticsDevice::detach() noexcept {
  frame_.store(nullptr, std::memory_order_seq_cst);
  // The scheduler marks itself busy before it loads the function: once it is not busy after the store
  // above, no call of the old function is under way or can start.
  while (frame_busy_.load(std::memory_order_seq_cst)) std::this_thread::yield();
}

// Servo path: codes, no exception, allocation or string (the HD code is kept in scheduler_error_).
DeviceFault OpenHapticsDevice::read_state(DeviceState& state) noexcept {
  if (!open_) return DeviceFault::not_open;
  if (const hd::HDerror error = scheduler_error_.load(std::memory_order_relaxed); error != hd::HD_SUCCESS) {
    forces_enabled_.store(false);
    return hd_servo_fault(error);
  }
  if (in_frame_.load(std::memory_order_relaxed)) {  // the device clock's tick: this frame's own state
    state = frame_state_;
    return DeviceFault::none;
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
  const bool in_frame = in_frame_.load(std::memory_order_relaxed);
  const double now = in_frame ? frame_state_.time_s : monotonic_seconds();
  if (!force_n.allFinite()) {
    forces_enabled_.store(false, std::memory_order_release);
    if (in_frame) {
      frame_force_ = Vec3::Zero();
      frame_force_set_ = true;
    }
    command_.store({0.0, 0.0, 0.0, now});
    return DeviceFault::non_finite_force;
  }
  const Vec3 limited = clamp_force_magnitude(force_n, info_.max_force_n);
  if (in_frame) {  // the device clock's tick: this frame sends it
    frame_force_ = limited;
    frame_force_set_ = true;
    return DeviceFault::none;
  }
  command_.store({limited.x(), limited.y(), limited.z(), now});
  return DeviceFault::none;
}

}  // namespace calligraphy::openhaptics
