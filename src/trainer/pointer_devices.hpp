#pragma once
// Input without a haptic device, registered as devices by the trainer (docs/devices.md):
//   "mouse"       2-DOF on the paper plane; the left button puts the pen on the paper; no force output
//                 (the paper's vision-only condition, section 7.1).
//   "mouse-hand"  a simulated Phantom Desktop whose stylus is held by a simulated hand coupled to the
//                 mouse through a hand impedance, so guidance visibly pulls the pen towards the stroke;
//                 from its first contact until the button is released the pen stays on the paper (one
//                 press, one touch: the stylus' bounce on landing is not a lift).
// The window thread writes the pointer (paper metres, button) and the servo thread reads it, lock-free.
#include <atomic>
#include <cstdint>

#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy::trainer {

/// The pointer as the window last saw it, in trial paper metres. Written by the window thread, read by
/// the servo thread: x and y are packed as two floats in one 64-bit atomic (so a reader never sees x of
/// one move and y of another), the button in another atomic. Floats resolve 0.1 um at 1 m.
class PointerInput {
 public:
  void set(double x_m, double y_m, bool pressed) noexcept;
  void set_pressed(bool pressed) noexcept { pressed_.store(pressed, std::memory_order_relaxed); }
  /// x, y [m] and the button, lock-free and wait-free.
  void get(double& x_m, double& y_m, bool& pressed) const noexcept;

 private:
  std::atomic<std::uint64_t> position_{0};
  std::atomic<bool> pressed_{false};
};

/// The process-wide pointer the "mouse" and "mouse-hand" devices read.
PointerInput& pointer_input();

/// The hand that couples "mouse-hand" to the pointer: a spring and damper to a target under the
/// pointer, pressed into the paper while the button is down and lifted otherwise. The figures are the
/// simulated novice writer's (simulated_writer.hpp).
struct MouseHandParameters {
  double stiffness_n_per_m = 150.0;  ///< hand stiffness [N/m]
  double damping_n_s_per_m = 3.0;    ///< hand damping [N s/m]
  double press_depth_m = 0.005;      ///< target below the paper while the button is down [m]
  double lift_height_m = 0.01;       ///< target above the paper while it is up [m]
};

/// Registers "mouse" and "mouse-hand" in `registry` (nothing for a name already taken).
void register_pointer_devices(DeviceRegistry& registry);

/// How far below the paper the "mouse" puts the pen while the button is down, and above it while up [m].
inline constexpr double kMousePressDepthM = 0.001;
inline constexpr double kMouseLiftHeightM = 0.005;

}  // namespace calligraphy::trainer
