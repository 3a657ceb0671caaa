#include "devices/phantom/phantom_arm.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "devices/phantom/velocity_filter.hpp"

using namespace calligraphy::phantom;
using calligraphy::Vec3;

namespace {
const JointAngles kPoses[] = {JointAngles(0.0, 0.0, 0.0), JointAngles(0.3, -0.4, 0.7),
                              JointAngles(-0.8, 0.6, -0.2), JointAngles(1.2, 1.0, 1.3)};
}

TEST_CASE("Forward kinematics matches Cavusoglu's published Phantom 1.5 formula", "[phantom][arm]") {
  const auto g = ArmGeometry::premium_1_5();
  CHECK(g.first_link_m == 0.20955);
  CHECK(g.second_link_m == 0.169545);
  // q = 0: first link horizontal, second link hanging down.
  CHECK((arm_frame_tip(g, JointAngles::Zero()) - Vec3(g.first_link_m, 0, -g.second_link_m)).norm() < 1e-15);
  // q2 = q3 = 90 degrees: first link up, second link horizontal.
  const Vec3 up = arm_frame_tip(g, JointAngles(0, std::numbers::pi / 2, std::numbers::pi / 2));
  CHECK((up - Vec3(g.second_link_m, 0, g.first_link_m)).norm() < 1e-12);
  // Base yaw turns the reach about z and leaves the height.
  const JointAngles q(0.5, 0.2, 0.4);
  const Vec3 tip = arm_frame_tip(g, q);
  const double reach = g.first_link_m * std::cos(0.2) + g.second_link_m * std::sin(0.4);
  CHECK(tip.x() == Approx(std::cos(0.5) * reach));
  CHECK(tip.y() == Approx(std::sin(0.5) * reach));
  CHECK(tip.z() == Approx(g.first_link_m * std::sin(0.2) - g.second_link_m * std::cos(0.4)));
  CHECK(relative_elbow_angle(q) == Approx(0.2));
}

TEST_CASE("Jacobian matches central finite differences of the forward kinematics", "[phantom][arm]") {
  const PhantomArm arm(ArmGeometry::omni(), JointAngles(0.1, 0.2, 0.3));
  const double h = 1e-6;
  for (const auto& q : kPoses) {
    const Eigen::Matrix3d analytic = arm.jacobian(q);
    const Eigen::Matrix3d analytic_arm = arm_frame_jacobian(arm.geometry(), q);
    for (int j = 0; j < 3; ++j) {
      JointAngles plus = q, minus = q;
      plus[j] += h;
      minus[j] -= h;
      const Vec3 numeric = (arm.tip_position(plus) - arm.tip_position(minus)) / (2 * h);
      const Vec3 numeric_arm =
          (arm_frame_tip(arm.geometry(), plus) - arm_frame_tip(arm.geometry(), minus)) / (2 * h);
      CHECK((analytic.col(j) - numeric).norm() < 1e-8);
      CHECK((analytic_arm.col(j) - numeric_arm).norm() < 1e-8);
    }
  }
}

TEST_CASE("Device frame: origin at the workspace centre, y away from the writer, z up", "[phantom][arm]") {
  const PhantomArm arm(ArmGeometry::omni());
  CHECK(arm.tip_position(JointAngles::Zero()).norm() < 1e-15);
  // Raising the first link lifts the tip and pulls it towards the writer (-y).
  const Vec3 raised = arm.tip_position(JointAngles(0, 0.1, 0));
  CHECK(raised.z() > 0.0);
  CHECK(raised.y() < 0.0);
  CHECK(std::abs(raised.x()) < 1e-15);
  // Positive base yaw turns the arm to the writer's left (-x).
  CHECK(arm.tip_position(JointAngles(0.1, 0, 0)).x() < 0.0);
}

TEST_CASE("Joint torques J^T F do the same virtual work as the tip force", "[phantom][arm]") {
  const PhantomArm arm(ArmGeometry::omni());
  const Vec3 force(0.7, -1.1, 2.0);
  for (const auto& q : kPoses) {
    const JointTorques tau = arm.joint_torques(q, force);
    const JointAngles dq(1e-7, -2e-7, 1.5e-7);
    const Vec3 dx = arm.tip_position(q + dq) - arm.tip_position(q);
    CHECK(tau.dot(dq) == Approx(force.dot(dx)).epsilon(1e-5));
  }
}

TEST_CASE("Encoder counts to joint angles and back", "[phantom][arm]") {
  JointEncoders encoders(15000, {1, -1, 1});
  const JointAngles inkwell(0.0, -0.2, -0.3);
  encoders.home({1234, -2345, 32000}, inkwell);
  REQUIRE(encoders.is_homed());
  CHECK(encoders.radians_per_count() == Approx(2 * std::numbers::pi / 15000));
  // At home the counts give the home angles.
  CHECK((encoders.angles({1234, -2345, 32000}) - inkwell).norm() < 1e-15);
  // 15,000 counts are one revolution; joint 2 counts down.
  const JointAngles turned = encoders.angles({1234 + 3750, -2345 + 3750, 32000});
  CHECK(turned[0] == Approx(inkwell[0] + std::numbers::pi / 2));
  CHECK(turned[1] == Approx(inkwell[1] - std::numbers::pi / 2));
  // Joint 3 crosses the int16 wrap (32000 + 1000 counts reads as -32536) and stays continuous.
  const JointAngles wrapped = encoders.angles({1234, -2345, -32536});
  CHECK(wrapped[2] == Approx(inkwell[2] + 1000 * encoders.radians_per_count()));
  for (const auto& q : kPoses) {
    const auto counts = encoders.counts(q);
    CHECK((encoders.angles(counts) - q).cwiseAbs().maxCoeff() <= 0.5 * encoders.radians_per_count() + 1e-12);
    CHECK(encoders.counts(encoders.angles(counts)) == counts);
  }
  CHECK_THROWS_AS(JointEncoders(0), calligraphy::InvalidArgument);
  CHECK_THROWS_AS(JointEncoders(15000, {1, 2, 1}), calligraphy::InvalidArgument);
}

TEST_CASE("Joint torques to DAC counts and back, saturation keeps the direction", "[phantom][arm]") {
  MotorModel motors;
  motors.direction = {1, -1, 1};
  const double per_count = motors.newton_metres_per_count(0);
  CHECK(per_count ==
        Approx(motors.gear_ratio[0] * motors.torque_constant_n_m_per_a * motors.amps_per_dac_count));
  CHECK(motors.newton_metres_per_count(1) == Approx(-per_count));

  const JointTorques tau(0.1, -0.05, 0.2);
  const auto counts = torques_to_dac(motors, tau);
  CHECK(counts[1] > 0);  // joint 2 is wired the other way round
  CHECK((dac_to_torques(motors, counts) - tau).cwiseAbs().maxCoeff() <= 0.5 * std::abs(per_count) + 1e-12);

  const JointTorques huge(3.0, -1.0, 0.5);  // far beyond full scale
  const auto saturated = torques_to_dac(motors, huge);
  CHECK(std::abs(saturated[0]) == 2047);
  const JointTorques back = dac_to_torques(motors, saturated);
  CHECK(back.normalized().dot(huge.normalized()) == Approx(1.0).epsilon(1e-6));

  const JointTorques nan(std::nan(""), 0.0, 0.0);
  CHECK(torques_to_dac(motors, nan) == std::array<std::int16_t, 3>{0, 0, 0});
}

TEST_CASE("Force clamp keeps the direction, non-finite force gives zero", "[devices][safety]") {
  using calligraphy::clamp_force_magnitude;
  const Vec3 f(3.0, 4.0, 0.0);
  CHECK(clamp_force_magnitude(f, 10.0) == f);
  const Vec3 clamped = clamp_force_magnitude(f, 2.5);
  CHECK(clamped.norm() == Approx(2.5));
  CHECK(clamped.normalized().dot(f.normalized()) == Approx(1.0));
  CHECK(clamp_force_magnitude(Vec3(std::nan(""), 0, 0), 3.3) == Vec3::Zero());
}

TEST_CASE("Velocity filter converges to a constant velocity and ignores stalled time",
          "[devices][velocity]") {
  calligraphy::devices::VelocityFilter filter(50.0);
  const Vec3 v(0.02, -0.01, 0.005);
  Vec3 estimate = filter.update(Vec3::Zero(), 0.0);
  CHECK(estimate == Vec3::Zero());
  for (int k = 1; k <= 200; ++k) estimate = filter.update(v * (k * 0.001), k * 0.001);
  CHECK((estimate - v).norm() < 1e-6);
  CHECK(filter.update(Vec3::Constant(5.0), 0.2) == estimate);  // same time stamp: no new estimate
}
