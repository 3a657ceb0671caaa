#pragma once
/// \file device_servo_clock.hpp
/// The servo thread of a device's own driver. Some drivers own the 1 kHz loop (OpenHaptics' HD
/// scheduler; any SDK with a servo callback): their thread reads the position and sends the force in one
/// frame. A `ServoLoop` on such a device runs its tick inside that frame, so the force computed from a
/// position is commanded in the same servo frame (as every OpenHaptics application and libfranka's
/// `Robot::control` do). A second, unsynchronised loop beside the driver's would answer a position one or
/// two frames late, which lowers the stiffness that stays passive (Colgate & Schenkel 1997:
/// b > K (T/2 + delay); docs/servo-loop.md).

namespace calligraphy {

/// A device's own servo clock (`HapticDevice::servo_clock()`). Implementations call the attached frame
/// function once per servo frame on the driver's thread, after the frame's state was read and before its
/// force is sent: inside the call, `read_state` returns that frame's state and the force given to
/// `write_force` is the one the frame sends. Not on the servo path itself: `attach` and `detach` are called
/// from a normal thread.
class DeviceServoClock {
 public:
  /// Called once per frame on the driver's servo thread. Same rules as the servo path: no allocation,
  /// lock, log, string or exception.
  using FrameFunction = void (*)(void* context) noexcept;

  virtual ~DeviceServoClock() = default;
  DeviceServoClock() = default;
  DeviceServoClock(const DeviceServoClock&) = delete;
  DeviceServoClock& operator=(const DeviceServoClock&) = delete;

  /// The driver's servo rate [Hz] while the device is open.
  [[nodiscard]] virtual double servo_rate_hz() const noexcept = 0;
  /// Starts calling `frame(context)` once per servo frame. Precondition: the device is open and nothing is
  /// attached. Throws DeviceError when the device is not open, StateError when a function is attached.
  virtual void attach(FrameFunction frame, void* context) = 0;
  /// Stops calling the frame function and returns once no call is under way (a call that started before
  /// returns first). Never throws; does nothing when nothing is attached. Must not be called from inside
  /// the frame function.
  virtual void detach() noexcept = 0;
};

}  // namespace calligraphy
