#pragma once
/// \file simulated_device.hpp
/// A simulated haptic device for tests and experiments: a point mass with viscous damping, pushed by
/// the hand holding it and by the commanded force, which is held for the servo tick (zero-order hold)
/// and saturated at the device's maximum. Physics runs in substeps finer than the servo tick; the
/// reported position is quantised to the encoder resolution and the velocity is a low-passed
/// difference of reported positions, as on a real device. Deterministic; no wall clock.
/// Model: m x'' = F_hand + F_device - b x' (a point-mass device with viscous damping, as in Colgate &
/// Schenkel, "Passivity of a class of sampled-data systems: application to haptic interfaces", 1997).
///
/// Stability for any step: `advance(dt)` never takes a substep longer than
/// min(1 / physics_rate_hz, m / b). Semi-implicit Euler on m v' = F - b v is stable for h b / m < 2, and
/// at h <= m / b it is also monotone (no overshoot of the terminal velocity F / b). The hand is a black
/// box to the device: its spring k_h and damper b_h need h < 2 sqrt(m / k_h) and h < 2 m / b_h, which the
/// default 10 kHz physics rate gives for the simulated writers (k_h <= 600 N/m, b_h <= 8 N s/m) on any
/// mass above 0.5 g; raise `physics_rate_hz` for a lighter device or a stiffer hand. At most
/// `kMaxSubstepsPerAdvance` substeps are taken per call; the time left after them is integrated with the
/// exact solution of the damped mass under the force held constant (see `advance`).
///
/// Time: the device's clock (`DeviceState::time_s`, `time()`) reads 0 at `open()` and moves only in
/// `advance`, in whole nanoseconds (its resolution), so that n ticks of 1 ms read exactly n ms, not a sum of
/// rounded steps (13.072999999980317 s for 13,073 ticks).
#include <cstdint>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// CHAI3D's figures for the Phantom Desktop (max 7.9 N, 1000 N/m, 5 N s/m, 0.10 m) and the datasheet's
/// continuous force 1.75 N and workspace 160 x 120 x 120 mm (the vendor's datasheet, as recalled).
[[nodiscard]] DeviceInfo simulated_phantom_desktop_info();

/// The simulated device's physics. Ranges are physical (a stylus, linkage and hand, not a crane or a
/// dust grain) and checked by `validate()`.
struct SimulatedDeviceParameters {
  double moving_mass_kg = 0.2;     ///< stylus, linkage and hand together [kg], in [1e-4, 1e3]
  double damping_n_s_per_m = 0.5;  ///< device viscous damping b [N s/m], in [0, 1e4]
  double encoder_resolution_m =
      2.3e-5;                        ///< position quantum (Desktop nominal 0.023 mm) [m]; 0 or [1e-9, 1e-3]
  double velocity_cutoff_hz = 50.0;  ///< low-pass on the differenced velocity [Hz], in (0, 1e6]
  /// Least number of integration steps per `advance` call, in [1, 10000]. With the default 10 and a 1 kHz
  /// servo tick the substep is 0.1 ms, exactly as before `physics_rate_hz` existed.
  int physics_substeps = 10;
  /// Least physics rate [Hz], in [1e3, 1e8]: no substep is longer than 1 / physics_rate_hz. 10 kHz is
  /// the rate the simulated writer's hand spring was tuned at ("physics at >= 10 kHz").
  double physics_rate_hz = 10000.0;
  Vec3 initial_position_m = Vec3(0.0, -0.05, 0.02);  ///< where the stylus starts [m]
  /// The figures it reports: its peak force saturates the force it is given and bounds a trial's safety
  /// chain; max_force_n > 0, every other figure >= 0, all finite.
  DeviceInfo info = simulated_phantom_desktop_info();

  /// Throws InvalidArgument naming the parameter, its value and its range when a value is out of range
  /// or not finite.
  void validate() const;
};

class SimulatedDevice final : public HandDrivenDevice {
 public:
  explicit SimulatedDevice(const SimulatedDeviceParameters& parameters = {});

  /// The hand moving the stylus (not owned; nullptr for a free device).
  void attach_hand(HandModel* hand) noexcept override { hand_ = hand; }
  /// Integrates the physics over `dt_s` seconds [s] with the force held since the last `write_force`.
  /// Any finite dt_s >= 0 is integrated stably: n = max(physics_substeps, ceil(dt_s / h_max)) semi-implicit
  /// Euler substeps of dt_s / n, h_max = min(1 / physics_rate_hz, m / b), at most
  /// `kMaxSubstepsPerAdvance` of them; the time left after those (only when dt_s exceeds
  /// kMaxSubstepsPerAdvance x h_max, e.g. 20 s at the defaults) follows the exact solution of
  /// m x'' = F - b x' with F the commanded force plus the hand's force at the start of that interval,
  /// held constant. The clock moves by dt_s rounded to whole nanoseconds. Throws InvalidArgument when dt_s
  /// is negative or not finite, or would take the clock past 2^62 ns (146 years) (the state is unchanged),
  /// or when the exact interval would take the state out of the range of a double (the state is then
  /// left after the substeps already taken).
  void advance(double dt_s) override;
  /// The most substeps one `advance` call takes (bounds its cost: about 10 ms of CPU without a hand).
  static constexpr long kMaxSubstepsPerAdvance = 200'000;

  [[nodiscard]] const DeviceInfo& info() const override { return parameters_.info; }
  /// Opens the device: its clock restarts at 0 s and its velocity filter afresh (the first read reports
  /// zero velocity); the stylus stays where it is. Opening an open device changes nothing. Never throws.
  void open() noexcept override;
  /// Closes the device: zero force, and reads and writes return `DeviceFault::not_open` until `open()`.
  void close() noexcept override;
  [[nodiscard]] bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override;
  [[nodiscard]] bool forces_enabled() const override { return forces_enabled_; }
  /// `DeviceFault::none`, except `DeviceFault::not_open` before `open()` and after `close()` (`state` is left
  /// untouched), and one misuse: with a hand attached, a read that follows a read and a `write_force` with
  /// no `advance` between them returns `DeviceFault::not_advanced` and turns forces off (the program forgot
  /// to let time pass: the pen would stay at rest while the hand writes). The tick order is read_state,
  /// write_force, advance(dt_s).
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override;
  /// `DeviceFault::none`, or `DeviceFault::not_open` before `open()` and after `close()`: zero force is then
  /// applied (the stylus moves only under the hand and its own momentum). Saturates at info().max_force_n
  /// keeping the direction; a non-finite force, or any force while forces are disabled, applies zero force.
  [[nodiscard]] DeviceFault write_force(const Vec3& force_n) noexcept override;

  /// The unquantised position and velocity, for tests [m], [m/s].
  [[nodiscard]] const Vec3& true_position() const noexcept { return position_; }
  [[nodiscard]] const Vec3& true_velocity() const noexcept { return velocity_; }
  /// The force actually applied after saturation [N].
  [[nodiscard]] const Vec3& applied_force() const noexcept { return force_; }
  /// The device's clock [s]: 0 at `open()` (and at construction), moved only by `advance`.
  [[nodiscard]] double time() const noexcept { return static_cast<double>(time_ns_) / 1e9; }

 private:
  SimulatedDeviceParameters parameters_;
  HandModel* hand_ = nullptr;
  bool open_ = false;
  bool forces_enabled_ = true;
  std::int64_t time_ns_ = 0;  // the clock in whole nanoseconds: exact, however many ticks it counts
  Vec3 position_;
  Vec3 velocity_ = Vec3::Zero();
  Vec3 force_ = Vec3::Zero();
  Vec3 reported_position_;
  Vec3 reported_velocity_ = Vec3::Zero();
  std::int64_t last_read_ns_ = 0;
  bool read_before_ = false;
  bool read_since_advance_ = false;  // read_state since the last advance
  bool written_since_read_ = false;  // write_force after that read

  void integrate_exactly(double duration_s, double start_s);
};

/// Registers a `SimulatedDevice` with default parameters as "simulated" in `registry` (one of the standard
/// backends, `register_standard_device_backends`); nothing when a backend of that name is already there.
/// Thread-safe.
void register_simulated_device(DeviceRegistry& registry);

}  // namespace calligraphy
