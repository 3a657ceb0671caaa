#include "testing/phantom_emulator.hpp"

#include <algorithm>
#include <utility>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::phantom {

EmulatorParameters emulator_matching(const PhantomDeviceConfig& config) {
  EmulatorParameters parameters;
  parameters.geometry = config.geometry;
  parameters.inkwell_rad = config.inkwell_rad;
  parameters.encoder_counts_per_revolution = config.encoder_counts_per_revolution;
  parameters.encoder_direction = config.encoder_direction;
  parameters.motors = config.motors;
  return parameters;
}

PhantomEmulator::PhantomEmulator(EmulatorParameters parameters)
    : parameters_(std::move(parameters)),
      encoders_(parameters_.encoder_counts_per_revolution, parameters_.encoder_direction),
      q_(parameters_.inkwell_rad),
      docked_(parameters_.start_docked) {
  if (!(parameters_.tick_s > 0.0) || parameters_.substeps < 1 || !(parameters_.watchdog_timeout_s > 0.0) ||
      !(parameters_.joint_inertia_kg_m2.minCoeff() > 0.0)) {
    throw InvalidArgument("PhantomEmulator: tick, substeps, watchdog timeout and inertia must be > 0");
  }
  // Power-on: the encoders read power_on_counts in the inkwell pose.
  encoders_.home(parameters_.power_on_counts, parameters_.inkwell_rad);
}

void PhantomEmulator::receive_from_host(std::span<const std::uint8_t> packet) noexcept {
  if (!connected_) return;
  CommandPacket command;
  if (decode_command(packet, command) != PacketError::none) {
    ++commands_rejected_;
    return;
  }
  ++commands_received_;
  last_command_time_s_ = time_s_;
  // Forces come on only on a 0 -> 1 toggle of the enable bit between consecutive packets.
  if (!command.force_enable) {
    forces_active_ = false;
  } else if (!previous_enable_bit_) {
    forces_active_ = true;
  }
  previous_enable_bit_ = command.force_enable;
  last_command_ = command;
}

JointTorques PhantomEmulator::motor_torques() const noexcept {
  if (!forces_active_ || !connected_) return JointTorques::Zero();
  return dac_to_torques(parameters_.motors, last_command_.dac_counts);
}

void PhantomEmulator::advance_one_tick() noexcept {
  if (forces_active_ && time_s_ - last_command_time_s_ > parameters_.watchdog_timeout_s) {
    forces_active_ = false;
    ++watchdog_trips_;
  }
  const double h = parameters_.tick_s / parameters_.substeps;
  for (int step = 0; step < parameters_.substeps; ++step) {
    const JointTorques tau =
        motor_torques() + external_torque_ - parameters_.joint_damping_n_m_s_per_rad.cwiseProduct(qd_);
    qd_ += h * tau.cwiseQuotient(parameters_.joint_inertia_kg_m2);  // semi-implicit Euler
    q_ += h * qd_;
    for (int j = 0; j < 3; ++j) {
      if (std::abs(q_[j]) > parameters_.joint_limit_rad) {
        q_[j] = std::clamp(q_[j], -parameters_.joint_limit_rad, parameters_.joint_limit_rad);
        qd_[j] = 0.0;
      }
    }
  }
  time_s_ += parameters_.tick_s;
  if (parameters_.undock_after_s >= 0.0 && time_s_ >= parameters_.undock_after_s) {
    docked_ = false;
    parameters_.undock_after_s = -1.0;
  }
  if (docked_) {  // the inkwell holds the stylus
    q_ = parameters_.inkwell_rad;
    qd_.setZero();
  }
}

std::size_t PhantomEmulator::send_to_host(std::span<std::uint8_t> buffer) noexcept {
  if (!connected_) return 0;
  advance_one_tick();
  if (silent_pending_ > 0) {
    --silent_pending_;
    return 0;
  }
  StatusPacket status;
  status.encoder_counts = encoders_.counts(q_);
  for (auto& pair : status.potentiometer_pairs) pair = {0x8000, 0x8000};  // gimbals centred
  status.buttons_pressed = buttons_;
  status.docked = docked_;
  status.packet_counter = packet_counter_++;

  std::array<std::uint8_t, kStatusPacketBytes + 4> bytes{};
  encode_status(status, std::span<std::uint8_t, kStatusPacketBytes>(bytes.data(), kStatusPacketBytes));
  std::size_t length = kStatusPacketBytes;
  if (malformed_pending_ > 0) {
    --malformed_pending_;
    std::fill_n(bytes.begin() + 6, 4, std::uint8_t{0});  // first potentiometer pair a = b = 0
  }
  if (short_pending_ > 0) {
    --short_pending_;
    length = short_bytes_;
  } else if (long_pending_ > 0) {
    --long_pending_;
    length = bytes.size();
  }
  length = std::min(length, buffer.size());
  std::copy_n(bytes.begin(), length, buffer.begin());
  return length;
}

void PhantomEmulator::disconnect() noexcept {
  connected_ = false;
  forces_active_ = false;  // no host, no power to the amplifiers
}

void PhantomEmulator::set_joint_angles(const JointAngles& q) noexcept {
  q_ = q;
  qd_.setZero();
}

void PhantomEmulator::send_short_packets(int count, std::size_t bytes) noexcept {
  short_pending_ = count;
  short_bytes_ = std::min(bytes, kStatusPacketBytes - 1);
}

EmulatedPhantom make_emulated_phantom(PhantomDeviceConfig config) {
  auto parameters = emulator_matching(config);
  return make_emulated_phantom(std::move(config), std::move(parameters));
}

EmulatedPhantom make_emulated_phantom(PhantomDeviceConfig config, EmulatorParameters parameters) {
  auto emulator = std::make_shared<PhantomEmulator>(std::move(parameters));
  // The clock holds a raw pointer: the device owns the transport, which owns the emulator, so the
  // emulator outlives every clock call the device makes.
  config.clock = [raw = emulator.get()] { return raw->time_s(); };
  auto transport = std::make_unique<devices::InMemoryTransport>(emulator);
  auto device = std::make_unique<PhantomDevice>(std::move(transport), std::move(config));
  return {std::move(device), std::move(emulator)};
}

EmulatedPhantomDevice::EmulatedPhantomDevice(PhantomDeviceConfig config)
    : EmulatedPhantomDevice(config, emulator_matching(config)) {}

EmulatedPhantomDevice::EmulatedPhantomDevice(PhantomDeviceConfig config, EmulatorParameters parameters)
    : arm_(parameters.geometry, config.workspace_centre_rad) {
  auto emulated = make_emulated_phantom(std::move(config), std::move(parameters));
  device_ = std::move(emulated.device);
  emulator_ = std::move(emulated.emulator);
}

void EmulatedPhantomDevice::attach_hand(HandModel* hand) noexcept {
  hand_ = hand;
  if (hand == nullptr) emulator_->set_external_torque(JointTorques::Zero());
}

void EmulatedPhantomDevice::advance(double dt_s) noexcept {
  emulator_->set_tick(dt_s);
  if (hand_ == nullptr) return;
  const JointAngles& q = emulator_->joint_angles();
  const Eigen::Matrix3d jacobian = arm_.jacobian(q);
  const Vec3 tip_velocity = jacobian * emulator_->joint_velocities();
  const Vec3 force = hand_->hand_force(emulator_->time_s(), arm_.tip_position(q), tip_velocity);
  emulator_->set_external_torque(jacobian.transpose() * force);
}

}  // namespace calligraphy::phantom
