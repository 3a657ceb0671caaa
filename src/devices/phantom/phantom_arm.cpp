#include "devices/phantom/phantom_arm.hpp"

#include <cmath>
#include <numbers>

#include "calligraphy/core/errors.hpp"
#include "devices/phantom/phantom_codec.hpp"

namespace calligraphy::phantom {
namespace {

// Device frame = arm frame turned -90 degrees about z: device x (right) = -arm y (left),
// device y (away) = arm x (along the arm), z unchanged.
Eigen::Matrix3d arm_to_device_rotation() noexcept {
  Eigen::Matrix3d r;
  r << 0, -1, 0,  //
      1, 0, 0,    //
      0, 0, 1;
  return r;
}

}  // namespace

Vec3 arm_frame_tip(const ArmGeometry& geometry, const JointAngles& q) noexcept {
  const double l1 = geometry.first_link_m;
  const double l2 = geometry.second_link_m;
  const double reach = l1 * std::cos(q[1]) + l2 * std::sin(q[2]);
  return {std::cos(q[0]) * reach, std::sin(q[0]) * reach, l1 * std::sin(q[1]) - l2 * std::cos(q[2])};
}

Eigen::Matrix3d arm_frame_jacobian(const ArmGeometry& geometry, const JointAngles& q) noexcept {
  const double l1 = geometry.first_link_m;
  const double l2 = geometry.second_link_m;
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
  const double c3 = std::cos(q[2]), s3 = std::sin(q[2]);
  const double reach = l1 * c2 + l2 * s3;
  Eigen::Matrix3d j;
  j << -s1 * reach, -c1 * l1 * s2, c1 * l2 * c3,  //
      c1 * reach, -s1 * l1 * s2, s1 * l2 * c3,    //
      0.0, l1 * c2, l2 * s3;
  return j;
}

PhantomArm::PhantomArm(ArmGeometry geometry, JointAngles workspace_centre_rad) noexcept
    : geometry_(geometry), origin_in_arm_frame_(arm_frame_tip(geometry, workspace_centre_rad)) {}

Vec3 PhantomArm::tip_position(const JointAngles& q) const noexcept {
  return arm_to_device_rotation() * (arm_frame_tip(geometry_, q) - origin_in_arm_frame_);
}

Eigen::Matrix3d PhantomArm::jacobian(const JointAngles& q) const noexcept {
  return arm_to_device_rotation() * arm_frame_jacobian(geometry_, q);
}

JointTorques PhantomArm::joint_torques(const JointAngles& q, const Vec3& force_n) const noexcept {
  return jacobian(q).transpose() * force_n;
}

JointEncoders::JointEncoders(int counts_per_revolution, std::array<int, 3> direction)
    : counts_per_revolution_(counts_per_revolution), direction_(direction) {
  if (counts_per_revolution <= 0) throw InvalidArgument("JointEncoders: counts per revolution must be > 0");
  for (const int d : direction) {
    if (d != 1 && d != -1) throw InvalidArgument("JointEncoders: each direction must be +1 or -1");
  }
}

void JointEncoders::home(const std::array<std::int16_t, 3>& counts, const JointAngles& home_rad) noexcept {
  home_counts_ = counts;
  home_rad_ = home_rad;
  homed_ = true;
}

double JointEncoders::radians_per_count() const noexcept {
  return 2.0 * std::numbers::pi / counts_per_revolution_;
}

JointAngles JointEncoders::angles(const std::array<std::int16_t, 3>& counts) const noexcept {
  JointAngles q;
  for (std::size_t j = 0; j < 3; ++j) {
    // Difference modulo 2^16: survives the int16 wrap of the raw counter.
    const auto delta = static_cast<std::int16_t>(static_cast<std::uint16_t>(counts[j] - home_counts_[j]));
    q[static_cast<Eigen::Index>(j)] =
        home_rad_[static_cast<Eigen::Index>(j)] + direction_[j] * delta * radians_per_count();
  }
  return q;
}

std::array<std::int16_t, 3> JointEncoders::counts(const JointAngles& q) const noexcept {
  std::array<std::int16_t, 3> raw{};
  for (std::size_t j = 0; j < 3; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const long delta = std::lround(direction_[j] * (q[i] - home_rad_[i]) / radians_per_count());
    raw[j] = static_cast<std::int16_t>(static_cast<std::uint16_t>(home_counts_[j] + delta));
  }
  return raw;
}

double MotorModel::newton_metres_per_count(int joint) const noexcept {
  return direction[static_cast<std::size_t>(joint)] * gear_ratio[joint] * torque_constant_n_m_per_a *
         amps_per_dac_count;
}

std::array<std::int16_t, 3> torques_to_dac(const MotorModel& motors, const JointTorques& tau) noexcept {
  Vec3 counts;
  for (int j = 0; j < 3; ++j) counts[j] = tau[j] / motors.newton_metres_per_count(j);
  if (!counts.allFinite()) return {};  // a NaN torque must never reach the motors
  // Saturate by a common factor so the torque direction survives; the range is asymmetric
  // (-2047..+2048), so use the smaller bound for both signs.
  const double limit = -static_cast<double>(kDacMinCounts);
  const double largest = counts.cwiseAbs().maxCoeff();
  if (largest > limit) counts *= limit / largest;
  std::array<std::int16_t, 3> raw{};
  for (int j = 0; j < 3; ++j)
    raw[static_cast<std::size_t>(j)] = static_cast<std::int16_t>(std::lround(counts[j]));
  return raw;
}

JointTorques dac_to_torques(const MotorModel& motors, const std::array<std::int16_t, 3>& counts) noexcept {
  JointTorques tau;
  for (int j = 0; j < 3; ++j)
    tau[j] = counts[static_cast<std::size_t>(j)] * motors.newton_metres_per_count(j);
  return tau;
}

}  // namespace calligraphy::phantom
