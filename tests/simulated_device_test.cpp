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
  CHECK(d.write_force(Vec3(0.5, 0.0, 0.0)) == DeviceFault::none);
  for (int i = 0; i < 100; ++i) d.advance(1e-3);
  // x = F t^2 / (2 m) at t = 0.1 s; semi-implicit Euler's error is h / t = 0.1 ms / 100 ms = 0.1 %.
  CHECK(d.true_position().x() == Approx(0.5 * 0.01 / (2 * p.moving_mass_kg)).epsilon(1.5e-3));
  CHECK(d.true_position().x() > 0.5 * 0.01 / (2 * p.moving_mass_kg));
}

TEST_CASE("The simulated device saturates and quantises like a real one", "[device]") {
  SimulatedDevice d;
  CHECK(d.write_force(Vec3(0.0, 30.0, 40.0)) == DeviceFault::none);
  CHECK(d.applied_force().norm() == Approx(simulated_phantom_desktop_info().max_force_n));
  d.enable_forces(false);
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  CHECK(d.applied_force().isZero());
  DeviceState state;
  CHECK(d.read_state(state) == DeviceFault::none);  // the simulated device never faults
  const double q = SimulatedDeviceParameters{}.encoder_resolution_m;
  CHECK(std::abs(state.position_m.x() / q - std::round(state.position_m.x() / q)) < 1e-6);
  SimulatedDeviceParameters bad;
  bad.moving_mass_kg = 0.0;
  CHECK_THROWS_AS(SimulatedDevice(bad), InvalidArgument);
}
