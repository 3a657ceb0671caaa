// The simulated device integrates any finite step stably: long steps are split into substeps no longer
// than min(1 / physics_rate_hz, m / b), the time beyond the substep budget follows the closed form of
// the damped mass, and non-finite steps and unphysical parameters are refused by name.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "hand_models.hpp"

using namespace calligraphy;
using Catch::Matchers::Contains;

namespace {

SimulatedDeviceParameters free_parameters(double mass_kg, double damping_n_s_per_m) {
  SimulatedDeviceParameters p;
  p.moving_mass_kg = mass_kg;
  p.damping_n_s_per_m = damping_n_s_per_m;
  p.initial_position_m = Vec3::Zero();
  return p;
}

// Displacement of a mass m with damping b, at rest at t = 0, under a constant force F:
// x(t) = (F / b) (t - tau (1 - e^(-t / tau))), tau = m / b.
double damped_displacement_m(double force_n, double mass_kg, double damping_n_s_per_m, double t_s) {
  const double tau = mass_kg / damping_n_s_per_m;
  return force_n / damping_n_s_per_m * (t_s + tau * std::expm1(-t_s / tau));
}

// Counts the physics substeps (one hand_force call each, plus one for the closed-form interval).
class CountingHand final : public HandModel {
 public:
  Vec3 hand_force(double, const Vec3&, const Vec3&) override {
    ++calls;
    return Vec3::Zero();
  }
  long calls = 0;
};

}  // namespace

TEST_CASE("advance(100 s) under 1 N gives the damped mass's analytic displacement", "[simulated_device]") {
  const SimulatedDeviceParameters p = free_parameters(0.2, 0.5);  // the defaults: tau = 0.4 s
  SimulatedDevice d(p);
  d.open();
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  d.advance(100.0);
  const double expected =
      damped_displacement_m(1.0, p.moving_mass_kg, p.damping_n_s_per_m, 100.0);  // 199.2 m
  // Semi-implicit Euler overshoots the transient by (F / b) h = 2 m/s x 0.1 ms; the closed form adds nothing.
  CHECK(d.true_position().x() == Approx(expected).margin(4e-4));
  CHECK(d.true_velocity().x() ==
        Approx(1.0 / p.damping_n_s_per_m).epsilon(1e-12));  // terminal velocity F / b
  CHECK(d.true_position().y() == 0.0);
  CHECK(d.time() == Approx(100.0).epsilon(1e-12));
  DeviceState state;
  CHECK(d.read_state(state) == DeviceFault::none);
  CHECK(state.position_m.allFinite());
  CHECK(state.velocity_m_s.allFinite());
}

TEST_CASE("Without damping a long step follows x = F t^2 / (2 m)", "[simulated_device]") {
  const SimulatedDeviceParameters p = free_parameters(0.2, 0.0);
  SimulatedDevice d(p);
  d.open();
  CHECK(d.write_force(Vec3(0.0, 0.0, -1.0)) == DeviceFault::none);
  d.advance(100.0);
  CHECK(d.true_position().z() == Approx(-1.0 * 100.0 * 100.0 / (2.0 * p.moving_mass_kg)).epsilon(1e-6));
  CHECK(d.true_velocity().z() == Approx(-1.0 * 100.0 / p.moving_mass_kg).epsilon(1e-12));
}

TEST_CASE("A heavily damped light device stays finite and reaches F / b", "[simulated_device]") {
  const SimulatedDeviceParameters p = free_parameters(1e-3, 1e3);  // tau = 1 us, a thousandth of a servo tick
  SimulatedDevice d(p);
  d.open();
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  for (int i = 0; i < 1000; ++i) d.advance(1e-3);
  CHECK(d.true_position().allFinite());
  CHECK(d.true_velocity().x() == Approx(1.0 / p.damping_n_s_per_m).epsilon(1e-9));
  // At h = m / b the first substep reaches F / b: the transient is overshot by (F / b) h = 1 nm.
  CHECK(d.true_position().x() ==
        Approx(damped_displacement_m(1.0, p.moving_mass_kg, p.damping_n_s_per_m, 1.0)).margin(2e-9));
  d.advance(100.0);
  CHECK(d.true_velocity().x() == Approx(1.0 / p.damping_n_s_per_m).epsilon(1e-9));
  CHECK(d.true_position().x() ==
        Approx(damped_displacement_m(1.0, p.moving_mass_kg, p.damping_n_s_per_m, 101.0)).epsilon(1e-6));
}

TEST_CASE("A light device held by a stiff hand settles where the hand and the force balance",
          "[simulated_device]") {
  // m / b = 10 us: a 0.1 ms substep (the old fixed split of a 1 ms tick) has h b / m = 10 and diverges.
  const SimulatedDeviceParameters p = free_parameters(1e-3, 100.0);
  SimulatedDevice d(p);
  const Vec3 target(0.01, 0.0, 0.0);
  testing::ImpedanceHand hand = testing::stiff_hand(target);  // 600 N/m, 8 N s/m
  d.attach_hand(&hand);
  d.open();
  CHECK(d.write_force(Vec3(-1.2, 0.0, 0.0)) == DeviceFault::none);
  // Overdamped: settles with the time constant (b + b_hand) / k = 0.18 s; 4 s is 22 of them.
  for (int i = 0; i < 4000; ++i) d.advance(1e-3);
  // k (x_target - x) + F = 0: x = x_target + F / k = 10 mm - 2 mm.
  CHECK(d.true_position().allFinite());
  CHECK(d.true_position().x() == Approx(target.x() - 1.2 / 600.0).margin(1e-9));
  CHECK(std::abs(d.true_velocity().x()) < 1e-9);
}

TEST_CASE("The substep is no longer than 1 / physics_rate_hz nor m / b, and the count per call is bounded",
          "[simulated_device]") {
  CountingHand hand;
  {
    SimulatedDevice d;  // defaults: 10 substeps of a 1 ms tick, as lock-step trials have always had
    d.attach_hand(&hand);
    d.advance(1e-3);
    CHECK(hand.calls == 10);
    hand.calls = 0;
    d.advance(0.05);  // 50 ms at 10 kHz physics
    CHECK(hand.calls == 500);
    hand.calls = 0;
    d.advance(0.0);
    CHECK(hand.calls == 0);
  }
  {
    hand.calls = 0;
    SimulatedDevice d(free_parameters(1e-3, 1e3));  // m / b = 1 us
    d.attach_hand(&hand);
    d.advance(1e-3);
    CHECK(hand.calls == 1000);
  }
  {
    hand.calls = 0;
    SimulatedDevice d;
    d.attach_hand(&hand);
    d.advance(100.0);  // a million substeps' worth: the budget, then the closed form (one more hand_force)
    CHECK(hand.calls == SimulatedDevice::kMaxSubstepsPerAdvance + 1);
    CHECK(d.time() == Approx(100.0).epsilon(1e-12));
  }
}

TEST_CASE("advance refuses a negative or non-finite step and leaves the device as it was",
          "[simulated_device]") {
  SimulatedDevice d;
  d.open();
  CHECK(d.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  d.advance(1e-3);
  const Vec3 position = d.true_position();
  const double time_s = d.time();
  for (const double dt : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                          std::numeric_limits<double>::quiet_NaN(), -1e-3}) {
    CHECK_THROWS_AS(d.advance(dt), InvalidArgument);
    CHECK_THROWS_WITH(d.advance(dt), Contains("dt_s"));
  }
  CHECK(d.true_position() == position);
  CHECK(d.time() == time_s);
}

TEST_CASE("Unphysical device parameters are refused, naming the parameter and its range",
          "[simulated_device]") {
  struct Case {
    const char* name;
    void (*set)(SimulatedDeviceParameters&);
  };
  const Case cases[] = {
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = 1e-300; }},
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = 0.0; }},
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = std::nan(""); }},
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = 1e6; }},
      {"damping_n_s_per_m", [](SimulatedDeviceParameters& p) { p.damping_n_s_per_m = 1e9; }},
      {"damping_n_s_per_m", [](SimulatedDeviceParameters& p) { p.damping_n_s_per_m = -0.1; }},
      {"damping_n_s_per_m",
       [](SimulatedDeviceParameters& p) { p.damping_n_s_per_m = std::numeric_limits<double>::infinity(); }},
      {"encoder_resolution_m", [](SimulatedDeviceParameters& p) { p.encoder_resolution_m = 1e-300; }},
      {"encoder_resolution_m", [](SimulatedDeviceParameters& p) { p.encoder_resolution_m = -2.3e-5; }},
      {"encoder_resolution_m", [](SimulatedDeviceParameters& p) { p.encoder_resolution_m = 0.1; }},
      {"physics_rate_hz", [](SimulatedDeviceParameters& p) { p.physics_rate_hz = 0.0; }},
      {"physics_rate_hz", [](SimulatedDeviceParameters& p) { p.physics_rate_hz = std::nan(""); }},
      {"physics_rate_hz", [](SimulatedDeviceParameters& p) { p.physics_rate_hz = 1e12; }},
      {"physics_substeps", [](SimulatedDeviceParameters& p) { p.physics_substeps = 0; }},
      {"velocity_cutoff_hz", [](SimulatedDeviceParameters& p) { p.velocity_cutoff_hz = std::nan(""); }},
  };
  for (const Case& c : cases) {
    SimulatedDeviceParameters p;
    c.set(p);
    INFO(c.name);
    CHECK_THROWS_AS(SimulatedDevice(p), InvalidArgument);
    CHECK_THROWS_WITH(p.validate(), Contains(c.name) && Contains(" must be "));
  }
  // The edges of the ranges are accepted.
  SimulatedDeviceParameters edges;
  edges.moving_mass_kg = 1e-4;
  edges.damping_n_s_per_m = 1e4;
  edges.encoder_resolution_m = 0.0;
  edges.physics_rate_hz = 1e3;
  CHECK_NOTHROW(edges.validate());
}
