#pragma once
/// \file phantom_emulator.hpp
/// An emulated Phantom for tests, in the spirit of libfranka's mock server: it speaks the packet codec
/// (phantom_codec.hpp) over an `InMemoryTransport`, so the whole `PhantomDevice` code path runs.
/// Each status packet the host reads advances emulated time by one tick and integrates the joints,
///   I q'' = tau_motor + tau_external - b q'   (diagonal inertia I [kg m^2], damping b [N m s/rad]),
/// with tau_motor decoded from the last command's DAC counts while forces are enabled. Like the
/// device, it needs the force-enable bit toggled 0 -> 1 on consecutive command packets, and has its
/// own watchdog: no command for `watchdog_timeout_s` of emulated time zeroes the motors.
/// Single-threaded: the host's read/write calls drive it.

#include <array>
#include <cstdint>
#include <memory>

#include "calligraphy/devices/hand_port.hpp"
#include "devices/phantom/phantom_arm.hpp"
#include "devices/phantom/phantom_codec.hpp"
#include "devices/phantom/phantom_device.hpp"
#include "testing/in_memory_transport.hpp"

namespace calligraphy::phantom {

/// The emulated arm's physical truth.
struct EmulatorParameters {
  ArmGeometry geometry = ArmGeometry::omni();
  JointAngles inkwell_rad = JointAngles(0.0, -0.2, -0.3);  ///< pose while docked [rad]
  int encoder_counts_per_revolution = kEncoderCountsPerRevolution;
  std::array<int, 3> encoder_direction = {1, 1, 1};
  MotorModel motors;
  /// Encoder counts at power-on, in the inkwell: incremental encoders start anywhere, which is why the
  /// host must home them.
  std::array<std::int16_t, 3> power_on_counts = {1234, -2345, 345};
  Vec3 joint_inertia_kg_m2 = Vec3::Constant(0.001);         ///< about 0.05 kg at 0.135 m [kg m^2]
  Vec3 joint_damping_n_m_s_per_rad = Vec3::Constant(0.01);  ///< about 0.5 N s/m at the tip [N m s/rad]
  double joint_limit_rad = 1.5;                             ///< every joint stays within +-limit [rad]
  double tick_s = 0.001;                                    ///< emulated time per status packet [s]
  int substeps = 10;                                        ///< integration steps per tick
  double watchdog_timeout_s = 0.05;                         ///< device-side watchdog [s]
  bool start_docked = true;                                 ///< power on with the stylus in the inkwell
  double undock_after_s = -1.0;  ///< lift the stylus out at this emulated time [s]; < 0: never
};

/// Emulator parameters that match a device config (same geometry, inkwell, encoders, motors).
[[nodiscard]] EmulatorParameters emulator_matching(const PhantomDeviceConfig& config);

class PhantomEmulator final : public devices::InMemoryPeer {
 public:
  /// Throws InvalidArgument for non-positive tick, substeps, inertia or watchdog timeout.
  explicit PhantomEmulator(EmulatorParameters parameters = {});

  // InMemoryPeer
  [[nodiscard]] bool connected() const noexcept override { return connected_; }
  void receive_from_host(std::span<const std::uint8_t> packet) noexcept override;
  std::size_t send_to_host(std::span<std::uint8_t> buffer) noexcept override;

  // Test controls.
  /// Unplugs: every later transport call returns `DeviceFault::link_lost`; the motors stop.
  void disconnect() noexcept;
  /// Stylus into (true) or out of the inkwell. Docked, the arm is held at the inkwell pose.
  void set_docked(bool docked) noexcept { docked_ = docked; }
  /// Puts the arm at `q` [rad] at rest (the hand moved it there).
  void set_joint_angles(const JointAngles& q) noexcept;
  /// Torque of the writer's hand on the joints [N m], held until changed.
  void set_external_torque(const JointTorques& tau) noexcept { external_torque_ = tau; }
  /// Emulated time per status packet [s], e.g. 1 / servo rate. Ignored unless finite and > 0.
  void set_tick(double tick_s) noexcept {
    if (tick_s > 0.0 && tick_s < 1.0) parameters_.tick_s = tick_s;
  }
  /// Bit i set: button i+1 pressed.
  void set_buttons(std::uint32_t pressed) noexcept { buttons_ = pressed; }
  /// The next `count` status packets have a potentiometer pair of zeros (malformed).
  void send_malformed_packets(int count) noexcept { malformed_pending_ = count; }
  /// The next `count` status packets are cut to `bytes` bytes.
  void send_short_packets(int count, std::size_t bytes = 20) noexcept;
  /// The next `count` status packets carry 4 extra bytes.
  void send_long_packets(int count) noexcept { long_pending_ = count; }
  /// The next `count` reads get nothing (the host sees timeouts); time still passes.
  void stay_silent(int count) noexcept { silent_pending_ = count; }

  // Observations.
  [[nodiscard]] const JointAngles& joint_angles() const noexcept { return q_; }
  [[nodiscard]] const Vec3& joint_velocities() const noexcept { return qd_; }
  /// Torques the motors apply now [N m]; zero unless forces are enabled on the device side.
  [[nodiscard]] JointTorques motor_torques() const noexcept;
  [[nodiscard]] bool forces_active() const noexcept { return forces_active_; }
  [[nodiscard]] bool docked() const noexcept { return docked_; }
  [[nodiscard]] double time_s() const noexcept { return time_s_; }
  [[nodiscard]] std::uint64_t commands_received() const noexcept { return commands_received_; }
  [[nodiscard]] std::uint64_t commands_rejected() const noexcept { return commands_rejected_; }
  [[nodiscard]] std::uint64_t watchdog_trips() const noexcept { return watchdog_trips_; }
  [[nodiscard]] const CommandPacket& last_command() const noexcept { return last_command_; }
  [[nodiscard]] const EmulatorParameters& parameters() const noexcept { return parameters_; }

 private:
  void advance_one_tick() noexcept;

  EmulatorParameters parameters_;
  JointEncoders encoders_;
  JointAngles q_;
  Vec3 qd_ = Vec3::Zero();
  JointTorques external_torque_ = JointTorques::Zero();
  CommandPacket last_command_;
  bool previous_enable_bit_ = false;
  bool forces_active_ = false;
  bool connected_ = true;
  bool docked_;
  std::uint32_t buttons_ = 0;
  double time_s_ = 0.0;
  double last_command_time_s_ = 0.0;
  std::uint16_t packet_counter_ = 0;
  int malformed_pending_ = 0;
  int short_pending_ = 0;
  std::size_t short_bytes_ = 20;
  int long_pending_ = 0;
  int silent_pending_ = 0;
  std::uint64_t commands_received_ = 0;
  std::uint64_t commands_rejected_ = 0;
  std::uint64_t watchdog_trips_ = 0;
};

/// A PhantomDevice wired to a fresh emulator over an InMemoryTransport. The device's clock is the
/// emulator's time, so tests are deterministic.
struct EmulatedPhantom {
  std::unique_ptr<PhantomDevice> device;
  std::shared_ptr<PhantomEmulator> emulator;
};
/// `config.clock` is replaced by the emulator's clock; `parameters` default to emulator_matching(config).
[[nodiscard]] EmulatedPhantom make_emulated_phantom(PhantomDeviceConfig config = phantom_omni_config());
[[nodiscard]] EmulatedPhantom make_emulated_phantom(PhantomDeviceConfig config,
                                                    EmulatorParameters parameters);

/// The emulated Phantom as one device that a simulated hand can move. Every `HapticDevice` call goes to
/// the `PhantomDevice` (the real code path: codec, arm model, watchdog, over the in-memory link); the
/// `HandPort` turns the hand's tip force into joint torques by the Jacobian transpose of the emulated
/// arm, tau = J(q)^T F, evaluated from the arm's true joint angles and velocities once per tick and held
/// over the tick (`PhantomEmulator::set_external_torque`). The emulator integrates a tick each time
/// the host reads a status packet, so `advance(dt)` sets the tick length and the hand torque, and the
/// next `read_state` moves the arm.
class EmulatedPhantomDevice final : public HandDrivenDevice {
 public:
  /// `parameters` default to emulator_matching(config). Throws InvalidArgument like PhantomDevice.
  explicit EmulatedPhantomDevice(PhantomDeviceConfig config = phantom_omni_config());
  EmulatedPhantomDevice(PhantomDeviceConfig config, EmulatorParameters parameters);

  [[nodiscard]] const DeviceInfo& info() const override { return device_->info(); }
  void open() override { device_->open(); }
  void close() noexcept override { device_->close(); }
  [[nodiscard]] bool is_open() const override { return device_->is_open(); }
  void calibrate() override { device_->calibrate(); }
  [[nodiscard]] bool is_calibrated() const override { return device_->is_calibrated(); }
  void enable_forces(bool enabled) override { device_->enable_forces(enabled); }
  [[nodiscard]] bool forces_enabled() const override { return device_->forces_enabled(); }
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override {
    return device_->read_state(state);
  }
  [[nodiscard]] DeviceFault write_force(const Vec3& force_n) noexcept override {
    return device_->write_force(force_n);
  }

  void attach_hand(HandModel* hand) noexcept override;
  void advance(double dt_s) noexcept override;

  /// The device side, for tests (unplug it, dock it, push it).
  [[nodiscard]] PhantomEmulator& emulator() noexcept { return *emulator_; }
  /// The host side.
  [[nodiscard]] PhantomDevice& phantom() noexcept { return *device_; }

 private:
  std::unique_ptr<PhantomDevice> device_;
  std::shared_ptr<PhantomEmulator> emulator_;
  PhantomArm arm_;  // the emulated arm's true geometry, in the device's frame
  HandModel* hand_ = nullptr;
};

}  // namespace calligraphy::phantom
