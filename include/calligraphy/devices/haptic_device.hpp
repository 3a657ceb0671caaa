#pragma once
/// \file haptic_device.hpp
/// The abstract haptic device (paper section 2.4, "device level"). All quantities are SI:
/// positions in m, velocities in m/s, forces in N, stiffness in N/m, damping in N s/m, time in s.
/// Device coordinates: x right, y away from the writer, z up out of the paper.

#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/core/device_types.hpp"

namespace calligraphy {

class DeviceServoClock;
class HandPort;

/// Abstract haptic device. Implementations: `SimulatedDevice` (simulated_device.hpp), the Phantom backends,
/// OpenHaptics.
/// `read_state` and `write_force` are the servo path, called from the servo thread at up to 10 kHz:
/// they are noexcept and return a `DeviceFault` code (device_fault.hpp) instead of throwing, and must
/// not allocate, lock, log or build a string, also when they fail (fixed messages; details go to
/// counters or plain records read later from another thread). On a fault the device turns its forces
/// off; the servo loop then zeroes the force, stops and reports the code, and
/// `throw_device_fault(code, info().model)` turns it into the typed exception off the servo path.
/// `open`, `calibrate` and `enable_forces(true)` are off the servo path and throw typed exceptions.
class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  HapticDevice() = default;
  HapticDevice(const HapticDevice&) = delete;
  HapticDevice& operator=(const HapticDevice&) = delete;

  /// Static facts of the device, SI units.
  [[nodiscard]] virtual const DeviceInfo& info() const = 0;

  /// Opens the connection. Throws DeviceNotFound or CommunicationError.
  virtual void open() = 0;
  /// Turns forces off and closes the connection. Never throws.
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual bool is_open() const = 0;

  /// Homes the encoders. Devices that need no calibration do nothing. Throws CalibrationNeeded when
  /// the device cannot calibrate itself now (e.g. a Phantom whose stylus is not in the inkwell).
  virtual void calibrate() {}
  /// False while positions are not meaningful and forces cannot be enabled until `calibrate()`
  /// succeeds (e.g. a Phantom whose encoders were not homed in the inkwell). Devices that need no
  /// calibration return true. Any thread.
  [[nodiscard]] virtual bool is_calibrated() const { return true; }

  /// Enables or disables force output. Disabled devices ignore `write_force`.
  virtual void enable_forces(bool enabled) = 0;
  [[nodiscard]] virtual bool forces_enabled() const = 0;

  /// Servo path: reads the current state into `state` and returns `DeviceFault::none`, or returns the
  /// fault (`state` then holds the last good state, or is untouched). Never throws or allocates.
  [[nodiscard]] virtual DeviceFault read_state(DeviceState& state) noexcept = 0;
  /// Servo path: commands a force [N] to be held until the next command (zero-order hold) and returns
  /// `DeviceFault::none`, or the fault (e.g. `non_finite_force`: zero force is commanded instead).
  /// Implementations clamp to `info().max_force_n` preserving direction. Never throws or allocates.
  [[nodiscard]] virtual DeviceFault write_force(const Vec3& force_n) noexcept = 0;

  /// The device driver's own servo thread (device_servo_clock.hpp), or nullptr when the device has none
  /// and the caller's loop is the clock (`ServoLoop`'s thread). A `ServoLoop` on a device with a clock runs
  /// each tick inside the driver's frame. Valid while the device is open.
  [[nodiscard]] virtual DeviceServoClock* servo_clock() noexcept { return nullptr; }
  /// The device's hand port (hand_port.hpp) when a simulated hand can move it and its time passes only when
  /// told to (the simulated device, the emulated Phantom), else nullptr (a person moves it). The one way to
  /// ask; its listing says the same (`DeviceCapabilities::moved_by_simulated_hand`).
  [[nodiscard]] virtual HandPort* hand_port() noexcept { return nullptr; }
};

}  // namespace calligraphy
