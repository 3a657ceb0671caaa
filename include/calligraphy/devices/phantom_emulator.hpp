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

#include "calligraphy/devices/in_memory_transport.hpp"
#include "calligraphy/devices/phantom.hpp"
#include "calligraphy/devices/phantom_arm.hpp"
#include "calligraphy/devices/phantom_codec.hpp"

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
  /// Unplugs: every later transport call throws CommunicationError; the motors stop.
  void disconnect() noexcept;
  /// Stylus into (true) or out of the inkwell. Docked, the arm is held at the inkwell pose.
  void set_docked(bool docked) noexcept { docked_ = docked; }
  /// Puts the arm at `q` [rad] at rest (the hand moved it there).
  void set_joint_angles(const JointAngles& q) noexcept;
  /// Torque of the writer's hand on the joints [N m], held until changed.
  void set_external_torque(const JointTorques& tau) noexcept { external_torque_ = tau; }
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

}  // namespace calligraphy::phantom
