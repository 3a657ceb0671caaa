#pragma once
/// \file hand_port.hpp
/// A simulated hand on a device: `HandModel` is the hand (a force from the stylus' state), and
/// `HandPort` is the optional interface of a device that such a hand can move (the simulated device,
/// the emulated Phantom). A trial on a device with a hand port runs lock-step with a simulated writer,
/// deterministic for a seed; a real device has no hand port (a person moves it) and runs in real time.
#include "calligraphy/core/geometry.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// The hand holding the stylus: the force it applies [N] given time [s], position [m], velocity [m/s].
class HandModel {
 public:
  virtual ~HandModel() = default;
  virtual Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) = 0;
};

/// A device whose stylus a `HandModel` can push, and whose time advances only when told to.
/// A device implements it by deriving from `HandDrivenDevice`; callers find it with
/// `HapticDevice::hand_port()`. Not thread-safe: the servo thread calls it between `write_force` and the
/// next `read_state`.
class HandPort {
 public:
  virtual ~HandPort() = default;
  /// The hand holding the stylus (not owned; nullptr: nobody holds it).
  virtual void attach_hand(HandModel* hand) noexcept = 0;
  /// Lets `dt_s` seconds of device time pass [s] under the force held since the last `write_force`
  /// and the hand's force. The next `read_state` reports the state after them. An implementation may
  /// throw InvalidArgument for a negative or non-finite dt_s (the simulated device does).
  virtual void advance(double dt_s) = 0;
};

/// The base of a device that a simulated hand moves: a `HapticDevice` that is its own `HandPort`
/// (`hand_port()` returns it), so that nobody needs to probe with dynamic_cast.
class HandDrivenDevice : public HapticDevice, public HandPort {
 public:
  [[nodiscard]] HandPort* hand_port() noexcept final { return this; }
};

}  // namespace calligraphy
