#pragma once
/// \file simulated_device.hpp
/// A simulated haptic device for tests and experiments: a point mass with viscous damping, pushed by
/// the hand holding it and by the commanded force, which is held for the servo tick (zero-order hold)
/// and saturated at the device's maximum. Physics runs in substeps finer than the servo tick; the
/// reported position is quantised to the encoder resolution and the velocity is a low-passed
/// difference of reported positions, as on a real device. Deterministic; no wall clock.
/// Model: m x'' = F_hand + F_device - b x', a point mass with viscous damping.
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/sim/hand_port.hpp"

namespace calligraphy {

/// CHAI3D's figures for the Phantom Desktop (max 7.9 N, 1000 N/m, 5 N s/m, 0.10 m) and the datasheet's
/// continuous force 1.75 N and workspace 160 x 120 x 120 mm (the vendor's datasheet, as recalled).
[[nodiscard]] DeviceInfo simulated_phantom_desktop_info();

struct SimulatedDeviceParameters {
  double moving_mass_kg = 0.2;                       ///< stylus, linkage and hand together [kg]
  double damping_n_s_per_m = 0.5;                    ///< device viscous damping b [N s/m]
  double encoder_resolution_m = 2.3e-5;              ///< position quantum (Desktop nominal 0.023 mm) [m]
  double velocity_cutoff_hz = 50.0;                  ///< low-pass on the differenced velocity [Hz]
  int physics_substeps = 10;                         ///< integration steps per `advance` call
  Vec3 initial_position_m = Vec3(0.0, -0.05, 0.02);  ///< where the stylus starts [m]
  DeviceInfo info = simulated_phantom_desktop_info();

  /// Throws InvalidArgument when a value is out of range.
  void validate() const;
};

class SimulatedDevice final : public HapticDevice, public HandPort {
 public:
  explicit SimulatedDevice(const SimulatedDeviceParameters& parameters = {});

  /// The hand moving the stylus (not owned; nullptr for a free device).
  void attach_hand(HandModel* hand) noexcept override { hand_ = hand; }
  /// Integrates the physics over `dt_s` seconds with the force held since the last `write_force`.
  void advance(double dt_s) noexcept override;

  [[nodiscard]] const DeviceInfo& info() const override { return parameters_.info; }
  void open() override { open_ = true; }
  void close() noexcept override;
  [[nodiscard]] bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override;
  [[nodiscard]] bool forces_enabled() const override { return forces_enabled_; }
  DeviceState read_state() override;
  void write_force(const Vec3& force_n) override;

  /// The unquantised position and velocity, for tests [m], [m/s].
  [[nodiscard]] const Vec3& true_position() const noexcept { return position_; }
  [[nodiscard]] const Vec3& true_velocity() const noexcept { return velocity_; }
  /// The force actually applied after saturation [N].
  [[nodiscard]] const Vec3& applied_force() const noexcept { return force_; }
  [[nodiscard]] double time() const noexcept { return time_; }

 private:
  SimulatedDeviceParameters parameters_;
  HandModel* hand_ = nullptr;
  bool open_ = false;
  bool forces_enabled_ = true;
  double time_ = 0.0;
  Vec3 position_;
  Vec3 velocity_ = Vec3::Zero();
  Vec3 force_ = Vec3::Zero();
  Vec3 reported_position_;
  Vec3 reported_velocity_ = Vec3::Zero();
  double last_read_time_ = 0.0;
  bool read_before_ = false;
};

/// Registers a `SimulatedDevice` with default parameters as "simulated" in `registry`; nothing when a
/// backend of that name is already there. Thread-safe.
void register_simulated_device(DeviceRegistry& registry);

/// The process-wide `device_registry()` with the simulated device registered: the registry that
/// `calligraphy trial --device NAME` and the by-name trial runner use.
[[nodiscard]] DeviceRegistry& device_registry_with_simulation();

}  // namespace calligraphy
