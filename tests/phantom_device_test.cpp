// PhantomDevice against the emulated Phantom: the real device code path over the in-memory transport.
#include "devices/phantom/phantom_device.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "calligraphy/core/errors.hpp"
#include "testing/in_memory_transport.hpp"
#include "testing/phantom_emulator.hpp"

using namespace calligraphy::phantom;
using calligraphy::CalibrationNeeded;
using calligraphy::CommunicationError;
using calligraphy::DeviceFault;
using calligraphy::DeviceState;
using calligraphy::SafetyFault;
using calligraphy::Vec3;

namespace {

// One servo-path read or write that must not fault.
DeviceState read(PhantomDevice& device) {
  DeviceState state;
  REQUIRE(device.read_state(state) == DeviceFault::none);
  return state;
}
void write(PhantomDevice& device, const Vec3& force) {
  REQUIRE(device.write_force(force) == DeviceFault::none);
}

EmulatedPhantom make_undocked(const JointAngles& pose) {
  const auto config = phantom_omni_config();
  auto parameters = emulator_matching(config);
  parameters.start_docked = false;
  auto emulated = make_emulated_phantom(config, parameters);
  emulated.emulator->set_joint_angles(pose);
  return emulated;
}

// Enables forces (the bit-0 packet) and commands one force (the bit-1 packet): the 0 -> 1 toggle.
void enable_and_toggle(PhantomDevice& device, const Vec3& force) {
  device.enable_forces(true);
  read(device);
  write(device, force);
}

}  // namespace

TEST_CASE("open() homes the encoders from the docked bit", "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  REQUIRE(emulator->docked());
  REQUIRE_FALSE(device->is_calibrated());
  device->open();
  CHECK(device->is_open());
  CHECK(device->is_calibrated());
  const PhantomArm arm(ArmGeometry::omni());
  const auto state = read(*device);
  // The emulator's encoders power on at non-zero counts; homing maps them to the inkwell pose.
  CHECK((device->joint_angles() - emulator->parameters().inkwell_rad).norm() < 1e-12);
  CHECK((state.position_m - arm.tip_position(emulator->parameters().inkwell_rad)).norm() < 1e-12);
  CHECK(state.time_s > 0.0);
}

TEST_CASE("Used uncalibrated: CalibrationNeeded until the stylus is docked", "[phantom][device]") {
  const JointAngles pose(0.4, 0.3, 0.2);
  auto [device, emulator] = make_undocked(pose);
  device->open();
  CHECK_FALSE(device->is_calibrated());
  CHECK_THROWS_AS(device->enable_forces(true), CalibrationNeeded);
  CHECK_FALSE(device->forces_enabled());
  CHECK_THROWS_AS(device->calibrate(), CalibrationNeeded);
  // Disabled forces: write_force commands nothing.
  write(*device, Vec3(1, 0, 0));
  CHECK_FALSE(emulator->forces_active());
  CHECK_FALSE(emulator->last_command().force_enable);

  emulator->set_docked(true);
  device->calibrate();
  CHECK(device->is_calibrated());
  // Lift the stylus and move it: positions now follow the arm model.
  emulator->set_docked(false);
  const JointAngles moved(-0.3, 0.1, 0.5);
  emulator->set_joint_angles(moved);
  const auto state = read(*device);
  const PhantomArm arm(ArmGeometry::omni());
  const double count_rad = 2 * 3.141592653589793 / kEncoderCountsPerRevolution;
  CHECK((device->joint_angles() - moved).cwiseAbs().maxCoeff() <= 0.5 * count_rad + 1e-12);
  CHECK((state.position_m - arm.tip_position(moved)).norm() < 0.135 * 3 * count_rad);
  CHECK_NOTHROW(device->enable_forces(true));
}

TEST_CASE("Forces need the enable-bit toggle, the arm is pushed along the commanded force",
          "[phantom][device]") {
  auto [device, emulator] = make_undocked(JointAngles(0.2, 0.3, 0.4));
  emulator->set_docked(true);
  device->open();
  emulator->set_docked(false);
  emulator->set_joint_angles(JointAngles(0.2, 0.3, 0.4));
  const Vec3 force(0.5, -0.3, 0.8);  // [N], below the Omni's 3.3 N

  const auto commands_before = emulator->commands_received();
  device->enable_forces(true);
  // enable_forces sends the first half of the toggle at once: bit 0, zero force.
  CHECK(emulator->commands_received() == commands_before + 1);
  CHECK_FALSE(emulator->last_command().force_enable);
  CHECK(emulator->last_command().dac_counts == std::array<std::int16_t, 3>{0, 0, 0});
  CHECK(emulator->motor_torques().isZero());
  const auto before = read(*device);
  write(*device, force);  // the first force after enabling is applied, not skipped
  REQUIRE(emulator->forces_active());
  CHECK(emulator->last_command().force_enable);
  // The motors apply J^T F, up to one DAC count.
  const PhantomArm arm(ArmGeometry::omni());
  const JointTorques expected = arm.joint_torques(device->joint_angles(), force);
  const double count_torque = MotorModel{}.newton_metres_per_count(0);
  CHECK((emulator->motor_torques() - expected).cwiseAbs().maxCoeff() <= 0.5 * count_torque + 1e-12);

  // Joint-space dynamics I q'' = J^T F move the tip along J I^-1 J^T F (not exactly along F).
  const Eigen::Matrix3d jacobian = arm.jacobian(device->joint_angles());
  const Vec3 predicted = jacobian * emulator->parameters().joint_inertia_kg_m2.cwiseInverse().asDiagonal() *
                         jacobian.transpose() * force;
  calligraphy::DeviceState state;
  for (int tick = 0; tick < 20; ++tick) {
    state = read(*device);
    write(*device, force);
  }
  const Vec3 moved = state.position_m - before.position_m;
  CHECK(moved.norm() > 1e-4);
  CHECK(moved.normalized().dot(predicted.normalized()) > 0.98);
  CHECK(moved.dot(force) > 0.0);  // the force does positive work
  CHECK(device->safety_events().clamped_commands == 0);
}

TEST_CASE("Forces above max_force_n are clamped keeping their direction", "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  device->open();
  const Vec3 too_much(10.0, 0.0, -10.0);
  enable_and_toggle(*device, too_much);
  REQUIRE(emulator->forces_active());
  const PhantomArm arm(ArmGeometry::omni());
  const Vec3 limited = too_much.normalized() * device->info().max_force_n;
  const JointTorques expected = arm.joint_torques(device->joint_angles(), limited);
  CHECK((emulator->motor_torques() - expected).cwiseAbs().maxCoeff() <=
        0.5 * MotorModel{}.newton_metres_per_count(0) + 1e-12);
  CHECK(device->safety_events().clamped_commands >= 1);
}

TEST_CASE("A NaN force sends zero force, turns forces off and returns non_finite_force",
          "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  device->open();
  enable_and_toggle(*device, Vec3(1.0, 0.0, 0.0));
  REQUIRE(emulator->forces_active());
  REQUIRE_FALSE(emulator->motor_torques().isZero());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(device->write_force(Vec3(0.5, nan, 0.0)) == DeviceFault::non_finite_force);
  CHECK(device->last_fault().fault == DeviceFault::non_finite_force);
  CHECK_FALSE(device->forces_enabled());
  CHECK_FALSE(emulator->forces_active());
  CHECK(emulator->motor_torques().isZero());
  CHECK(emulator->last_command().dac_counts == std::array<std::int16_t, 3>{0, 0, 0});
  CHECK(device->safety_events().non_finite_commands == 1);
  CHECK(device->is_open());  // a safety fault is not a link fault
}

TEST_CASE("A disconnect mid-stream returns link_lost and leaves forces off", "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  device->open();
  enable_and_toggle(*device, Vec3(0.0, 1.0, 0.0));
  for (int tick = 0; tick < 5; ++tick) {
    read(*device);
    write(*device, Vec3(0.0, 1.0, 0.0));
  }
  REQUIRE(emulator->forces_active());
  emulator->disconnect();
  DeviceState state;
  CHECK(device->read_state(state) == DeviceFault::link_lost);
  CHECK(device->last_fault().fault == DeviceFault::link_lost);
  CHECK_FALSE(device->forces_enabled());
  CHECK_FALSE(device->is_open());
  CHECK(emulator->motor_torques().isZero());
  CHECK(device->write_force(Vec3(0.0, 1.0, 0.0)) == DeviceFault::not_open);
  device->close();  // must not throw on a dead link
  // Off the servo path, the one mapping makes the code a typed exception.
  CHECK_THROWS_AS(calligraphy::throw_device_fault(DeviceFault::link_lost, device->info().model),
                  CommunicationError);
}

TEST_CASE("A stream of bad packets becomes no_valid_status after the limit, with forces zeroed",
          "[phantom][device]") {
  auto config = phantom_omni_config();
  config.max_consecutive_bad_packets = 10;
  auto [device, emulator] = make_emulated_phantom(config);
  device->open();
  enable_and_toggle(*device, Vec3(0.0, 0.0, 1.0));
  REQUIRE(emulator->forces_active());
  emulator->send_malformed_packets(100);
  DeviceState state;
  for (int reads = 1; reads < 10; ++reads) CHECK(device->read_state(state) == DeviceFault::none);
  CHECK(device->read_state(state) == DeviceFault::no_valid_status);
  // The detail is plain data, worded only off the servo path.
  const PhantomFaultRecord& record = device->last_fault();
  CHECK(record.fault == DeviceFault::no_valid_status);
  CHECK(record.bad_reads == 10);
  CHECK(record.last_packet_error == PacketError::bad_potentiometer);
  CHECK_FALSE(record.last_read_timed_out);
  CHECK(describe(record).find("10 reads in a row without a valid status packet, the last rejected: "
                              "bad_potentiometer") != std::string::npos);
  // The link still carries commands, and the last one the device got turns forces off.
  CHECK_FALSE(emulator->forces_active());
  CHECK_FALSE(emulator->last_command().force_enable);
  CHECK(emulator->last_command().dac_counts == std::array<std::int16_t, 3>{0, 0, 0});
  CHECK_FALSE(device->is_open());
  CHECK(device->packet_errors().malformed == 10);
}

TEST_CASE("Malformed, short and long packets are counted and reported, the last good state is kept",
          "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  device->open();
  const auto good = read(*device);
  emulator->send_malformed_packets(3);
  for (int i = 0; i < 3; ++i) CHECK(read(*device).time_s == good.time_s);
  emulator->send_short_packets(2, 20);
  for (int i = 0; i < 2; ++i) CHECK(read(*device).time_s == good.time_s);
  emulator->send_short_packets(1, 0);  // empty packet: seen as a timeout
  CHECK(read(*device).time_s == good.time_s);
  emulator->send_long_packets(1);
  CHECK(read(*device).time_s == good.time_s);
  emulator->stay_silent(2);
  for (int i = 0; i < 2; ++i) CHECK(read(*device).time_s == good.time_s);
  const auto next = read(*device);
  CHECK(next.time_s > good.time_s);

  const auto errors = device->packet_errors();
  CHECK(errors.malformed == 3);
  CHECK(errors.too_short == 2);
  CHECK(errors.too_long == 1);
  CHECK(errors.timeouts == 3);
  CHECK(errors.rejected() == 6);
  // Rejected packets still used packet numbers (silent reads did not): those are lost.
  CHECK(errors.lost_packets == 7);
  CHECK(device->is_open());
}

TEST_CASE("Host watchdog: no write_force for longer than the timeout turns forces off", "[phantom][device]") {
  auto config = phantom_omni_config();
  config.watchdog_timeout_s = 0.02;
  auto [device, emulator] = make_emulated_phantom(config);
  device->open();
  enable_and_toggle(*device, Vec3(1.0, 0.0, 0.0));
  REQUIRE(emulator->forces_active());
  int reads = 0;
  bool tripped = false;
  DeviceState state;
  while (reads < 100 && !tripped) {
    const DeviceFault fault = device->read_state(state);
    if (fault == DeviceFault::none) {
      ++reads;
    } else {
      CHECK(fault == DeviceFault::watchdog);
      tripped = true;
    }
  }
  REQUIRE(tripped);
  CHECK(reads >= 19);  // 1 ms per read: not before the 20 ms timeout
  CHECK(reads <= 22);
  CHECK_FALSE(device->forces_enabled());
  CHECK_FALSE(
      emulator->forces_active());  // the host sent a forces-off packet, before the device's own watchdog
  CHECK(emulator->watchdog_trips() == 0);
  CHECK(device->safety_events().watchdog_trips == 1);
  // Forces come back only when asked for again.
  enable_and_toggle(*device, Vec3(1.0, 0.0, 0.0));
  CHECK(emulator->forces_active());
}

TEST_CASE("Device-side watchdog of the emulator drops forces when commands stop", "[phantom][emulator]") {
  auto emulator = std::make_shared<PhantomEmulator>();
  calligraphy::devices::InMemoryTransport link(emulator);
  link.open();
  std::array<std::uint8_t, kCommandPacketBytes> packet{};
  CommandPacket command;
  command.dac_counts = {100, 0, 0};
  encode_command(command, packet);  // enable bit 0
  REQUIRE(link.write(packet, std::chrono::milliseconds(1)) == DeviceFault::none);
  command.force_enable = true;
  encode_command(command, packet);  // then 1
  REQUIRE(link.write(packet, std::chrono::milliseconds(1)) == DeviceFault::none);
  REQUIRE(emulator->forces_active());
  // 1 again is not a new toggle, stays on
  REQUIRE(link.write(packet, std::chrono::milliseconds(1)) == DeviceFault::none);
  REQUIRE(emulator->forces_active());
  std::array<std::uint8_t, 64> status{};
  std::size_t received = 0;
  for (int tick = 0; tick < 60; ++tick)
    REQUIRE(link.read(status, std::chrono::milliseconds(1), received) == DeviceFault::none);
  CHECK_FALSE(emulator->forces_active());
  CHECK(emulator->watchdog_trips() == 1);
  CHECK(emulator->motor_torques().isZero());
  // Holding the bit at 1 does not re-enable; only a new 0 -> 1 toggle does.
  REQUIRE(link.write(packet, std::chrono::milliseconds(1)) == DeviceFault::none);
  CHECK_FALSE(emulator->forces_active());
  // Unplugged, then closed: codes, not exceptions.
  emulator->disconnect();
  CHECK(link.write(packet, std::chrono::milliseconds(1)) == DeviceFault::link_lost);
  CHECK(link.read(status, std::chrono::milliseconds(1), received) == DeviceFault::link_lost);
  CHECK(received == 0);
}

TEST_CASE("Buttons and velocity come through the whole path", "[phantom][device]") {
  auto [device, emulator] = make_emulated_phantom();
  device->open();
  emulator->set_docked(false);
  emulator->set_buttons(2);
  CHECK(read(*device).buttons == 2U);
  // A hand torque on the base joint swings the tip sideways; the filtered velocity must match the mean
  // velocity over the last 20 ms (the filter's lag, about 3 ms, is small against that).
  emulator->set_external_torque(JointTorques(0.02, 0.0, 0.0));
  for (int tick = 0; tick < 190; ++tick) read(*device);
  const auto earlier = read(*device);
  for (int tick = 0; tick < 19; ++tick) read(*device);
  const auto state = read(*device);
  const Vec3 mean_velocity = (state.position_m - earlier.position_m) / (state.time_s - earlier.time_s);
  CHECK(state.time_s - earlier.time_s == Approx(0.02));
  CHECK(mean_velocity.norm() > 0.05);
  CHECK((state.velocity_m_s - mean_velocity).norm() < 0.1 * mean_velocity.norm());
}

TEST_CASE("Closed or null transports are refused", "[phantom][device]") {
  CHECK_THROWS_AS(PhantomDevice(nullptr, phantom_omni_config()), calligraphy::InvalidArgument);
  auto [device, emulator] = make_emulated_phantom();
  DeviceState state;
  CHECK(device->read_state(state) == DeviceFault::not_open);
  CHECK(device->write_force(Vec3::Zero()) == DeviceFault::not_open);
  CHECK_THROWS_AS(device->enable_forces(true), calligraphy::DeviceError);
  emulator->disconnect();
  CHECK_THROWS_AS(device->open(), calligraphy::DeviceNotFound);
}

TEST_CASE("open() on a link that never answers throws CommunicationError with the fault's detail",
          "[phantom][device]") {
  // Off the servo path the same code becomes the typed exception (throw_device_fault), with the detail
  // the device recorded as plain data.
  auto config = phantom_omni_config();
  config.max_consecutive_bad_packets = 5;
  auto [device, emulator] = make_emulated_phantom(config);
  emulator->stay_silent(100);
  CHECK_THROWS_WITH(device->open(),
                    Catch::Matchers::StartsWith(calligraphy::device_fault_message(
                        DeviceFault::no_valid_status, device->info().model)) &&
                        Catch::Matchers::Contains("5 reads in a row without a valid status packet, the last "
                                                  "a timeout"));
  CHECK_FALSE(device->is_open());
  CHECK(device->last_fault().fault == DeviceFault::no_valid_status);
}
