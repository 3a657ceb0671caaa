#include "calligraphy/devices/simulated_device.hpp"

#include <catch2/catch.hpp>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

TEST_CASE("A free simulated device accelerates as F = m a under a held force", "[device]") {
  SimulatedDeviceParameters p;
  p.damping_n_s_per_m = 0.0;
  p.encoder_resolution_m = 0.0;
  p.initial_position_m = Vec3::Zero();
  SimulatedDevice d(p);
  d.open();
  CHECK(d.write_force(Vec3(0.5, 0.0, 0.0)) == DeviceFault::none);
  for (int i = 0; i < 100; ++i) d.advance(1e-3);
  // x = F t^2 / (2 m) at t = 0.1 s; semi-implicit Euler's error is h / t = 0.1 ms / 100 ms = 0.1 %.
  CHECK(d.true_position().x() == Approx(0.5 * 0.01 / (2 * p.moving_mass_kg)).epsilon(1.5e-3));
  CHECK(d.true_position().x() > 0.5 * 0.01 / (2 * p.moving_mass_kg));
}

TEST_CASE("The simulated device saturates and quantises like a real one", "[device]") {
  SimulatedDevice d;
  d.open();
  CHECK(d.write_force(Vec3(0.0, 30.0, 40.0)) == DeviceFault::none);
  CHECK(d.applied_force().norm() == Approx(simulated_phantom_desktop_info().max_force_n));
  d.enable_forces(false);
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  CHECK(d.applied_force().isZero());
  DeviceState state;
  CHECK(d.read_state(state) == DeviceFault::none);  // an open simulated device never faults
  const double q = SimulatedDeviceParameters{}.encoder_resolution_m;
  CHECK(std::abs(state.position_m.x() / q - std::round(state.position_m.x() / q)) < 1e-6);
  SimulatedDeviceParameters bad;
  bad.moving_mass_kg = 0.0;
  CHECK_THROWS_AS(SimulatedDevice(bad), InvalidArgument);
}

TEST_CASE("The simulated device's clock reads 0 at open() and counts whole ticks", "[device]") {
  SimulatedDevice d;
  DeviceState state;
  d.open();
  CHECK(d.read_state(state) == DeviceFault::none);
  CHECK(state.time_s == 0.0);
  for (int i = 0; i < 13073; ++i) d.advance(1e-3);
  CHECK(d.read_state(state) == DeviceFault::none);
  // Exact, not a sum of 130,730 rounded substeps: 13,073 ticks of 1 ms read 13.073 s.
  CHECK(state.time_s == 13.073);
  d.open();  // already open: nothing changes
  CHECK(d.time() == 13.073);

  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  for (int i = 0; i < 100; ++i) d.advance(1e-3);
  d.close();
  const Vec3 position = d.true_position();
  d.open();  // the clock restarts; the stylus stays where it was
  CHECK(d.time() == 0.0);
  CHECK(d.true_position() == position);
  CHECK(d.read_state(state) == DeviceFault::none);
  CHECK(state.time_s == 0.0);
  // The velocity filter starts afresh: nothing differenced across the re-open.
  CHECK(state.velocity_m_s.isZero());
  for (int i = 0; i < 250; ++i) d.advance(1e-3);
  CHECK(d.read_state(state) == DeviceFault::none);
  CHECK(state.time_s == 0.25);
}

TEST_CASE("A simulated device not open reads and writes nothing: not_open and zero force", "[device]") {
  SimulatedDeviceParameters p;
  p.damping_n_s_per_m = 0.0;
  p.encoder_resolution_m = 0.0;
  p.initial_position_m = Vec3::Zero();
  SimulatedDevice d(p);
  DeviceState state;
  state.time_s = 42.0;
  // Before open(): as every device, a link fault, the state untouched and no force applied.
  CHECK(d.read_state(state) == DeviceFault::not_open);
  CHECK(state.time_s == 42.0);
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::not_open);
  CHECK(d.applied_force().isZero());
  d.advance(1e-2);
  CHECK(d.true_position().isZero());
  CHECK(is_link_fault(DeviceFault::not_open));

  d.open();
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  CHECK(d.applied_force().x() == 1.0);
  d.advance(1e-2);
  d.close();  // zero force: the stylus keeps only its momentum
  CHECK(d.applied_force().isZero());
  const Vec3 velocity = d.true_velocity();
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::not_open);
  CHECK(d.applied_force().isZero());
  d.advance(1e-2);
  CHECK(velocity.x() > 0.0);
  CHECK(d.true_velocity() == velocity);  // no force acted: undamped, it coasts
  CHECK(d.read_state(state) == DeviceFault::not_open);
  CHECK(state.time_s == 42.0);

  d.open();  // open again: reads and writes work, the force acts
  CHECK(d.read_state(state) == DeviceFault::none);
  CHECK(state.time_s == 0.0);
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  d.advance(1e-2);
  CHECK(d.true_velocity().x() == Approx(2.0 * 1e-2 / p.moving_mass_kg));  // 10 ms under 1 N, twice
}

TEST_CASE("The simulated device refuses a step that would run its clock past 2^62 ns", "[device]") {
  SimulatedDevice d;
  d.advance(1.0);
  CHECK_THROWS_AS(d.advance(4.7e9), InvalidArgument);  // 149 years
  CHECK(d.time() == 1.0);
}

TEST_CASE("The simulated device starts within a layout's reach", "[device]") {
  SimulatedDeviceParameters p;
  p.initial_position_m = Vec3(1.0, -1.0, 0.5);
  CHECK_NOTHROW(p.validate());
  p.initial_position_m = Vec3(0.0, 1e308, 0.0);
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("initial_position_m") && Catch::Contains("[-1, 1] m"));
}
