#pragma once
// HapticDevice over OpenHaptics' HDAPI, loaded at run time (hd_library.hpp). Tested against a stand-in
// libHD written from the public HDAPI reference (tests/hd_stand_in), never against 3D Systems' own.
//
// OpenHaptics owns the 1 kHz loop: an asynchronous scheduler callback brackets each servo frame with
// hdBeginFrame/hdEndFrame, reads position (mm), velocity (mm/s) and buttons, and sets the force (N). The
// device is its own servo clock (device_servo_clock.hpp): with a frame function attached (a ServoLoop),
// the callback calls it between the reads and the force, so the force answers the position of the same
// frame. Without one, read_state/write_force exchange data with the callback through sequence locks (no
// locks, no allocation) and the force is the latest command, one frame or more behind.
#include <atomic>
#include <memory>
#include <string>

#include "calligraphy/devices/device_servo_clock.hpp"
#include "calligraphy/devices/haptic_device.hpp"
#include "devices/openhaptics/hd_library.hpp"
#include "devices/openhaptics/seqlock.hpp"

namespace calligraphy::openhaptics {

class OpenHapticsDevice final : public HapticDevice, public DeviceServoClock {
 public:
  /// `configuration_name`: an OpenHaptics device configuration name; empty for HD_DEFAULT_DEVICE.
  /// `watchdog_timeout_s` [s]: without a frame function attached, no write_force for this long turns
  /// forces off. `servo_rate_hz`: the HD scheduler's rate (hdSetSchedulerRate; devices accept 500, 1000
  /// and some 2000). Throws InvalidArgument for a timeout <= 0 or a rate outside [100, 10000] Hz.
  explicit OpenHapticsDevice(std::string configuration_name = {}, double watchdog_timeout_s = 0.05,
                             double servo_rate_hz = 1000.0);
  ~OpenHapticsDevice() override;

  /// Valid after open(); before, a placeholder with zero limits.
  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  /// Loads libHD, initialises the device, reads its nominal limits, starts the scheduler. Throws
  /// DeviceNotFound ("OpenHaptics not found" with the paths tried, or hdInitDevice failed) or the
  /// mapped HD error (CommunicationError, SafetyFault, DeviceError).
  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const override { return open_; }
  /// hdCheckCalibration, then hdUpdateCalibration with the device's automatic style when an update is
  /// needed. Throws CalibrationNeeded when the device needs manual input (inkwell: dock the stylus).
  void calibrate() override;
  [[nodiscard]] bool is_calibrated() const override { return calibrated_.load(std::memory_order_acquire); }
  /// Throws CalibrationNeeded when enabling an uncalibrated device, DeviceError when not open.
  void enable_forces(bool enabled) override;
  [[nodiscard]] bool forces_enabled() const override {
    return forces_enabled_.load(std::memory_order_acquire);
  }
  /// Servo path. Faults: `driver_error` (link errors and any non-safety HD error from the scheduler),
  /// `safety_limit` (HD force/velocity/temperature errors), `watchdog`, `not_open`; forces are then off.
  /// The HD error code itself is kept (`servo_error`) and logged at close(), off the servo path.
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override;
  /// Servo path. Clamps to info().max_force_n keeping the direction. Faults: `non_finite_force` on a NaN
  /// or infinite component (zero force, forces off), `not_open`.
  [[nodiscard]] DeviceFault write_force(const Vec3& force_n) noexcept override;
  /// The first HD error the scheduler callback saw since open() (HD_SUCCESS: none). Any thread.
  [[nodiscard]] hd::HDerror servo_error() const noexcept { return scheduler_error_.load(); }

  /// The HD scheduler is this device's servo clock.
  [[nodiscard]] DeviceServoClock* servo_clock() noexcept override { return this; }
  [[nodiscard]] double servo_rate_hz() const noexcept override { return servo_rate_hz_; }
  /// Throws DeviceError when not open, StateError when a frame function is attached already.
  void attach(FrameFunction frame, void* context) override;
  void detach() noexcept override;

 private:
  static hd::HDCallbackCode servo_tick(void* self) noexcept;
  static hd::HDCallbackCode calibration_check(void* self) noexcept;
  void read_info();
  /// Runs `function(this)` once in the HD scheduler's thread and waits for it: at most 5 s, and not past a
  /// stop signal (stop_signals.hpp). Throws DeviceError naming the library when it did not run.
  void call_in_scheduler(hd::SchedulerCallback function, const char* what);
  // Stops the driver's scheduler and disables the device, waiting at most kSchedulerCallTimeoutS.
  void stop_driver_bounded() noexcept;

  void publish_frame_state() noexcept;  // frame_state_ for readers on other threads

  std::string configuration_name_;
  double watchdog_timeout_s_;
  double servo_rate_hz_;
  std::shared_ptr<const HdLibrary> library_;
  hd::HHD handle_ = hd::HD_INVALID_HANDLE;
  hd::HDSchedulerHandle servo_callback_ = 0;
  DeviceInfo info_;
  bool open_ = false;
  std::atomic<bool> forces_enabled_{false};
  std::atomic<bool> calibrated_{false};
  std::atomic<hd::HDerror> scheduler_error_{hd::HD_SUCCESS};  // first error seen by the callback
  std::atomic<bool> watchdog_tripped_{false};
  hd::HDenum calibration_result_ = hd::HD_CALIBRATION_OK;  // written by the synchronous calibration call
  SeqLocked<8> state_;    // position m (3), velocity m/s (3), buttons, time s
  SeqLocked<4> command_;  // force N in device frame (3), time s of the write

  // The attached frame function (device clock). `frame_busy_` is set by the scheduler around its check
  // and call, so that detach() can wait until no call is under way.
  std::atomic<FrameFunction> frame_{nullptr};
  std::atomic<void*> frame_context_{nullptr};
  std::atomic<bool> frame_busy_{false};
  // Inside a frame call, on the scheduler thread only: the frame's state and the force it will send.
  std::atomic<bool> in_frame_{false};
  DeviceState frame_state_;
  Vec3 frame_force_ = Vec3::Zero();
  bool frame_force_set_ = false;
};

}  // namespace calligraphy::openhaptics
