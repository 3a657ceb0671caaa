#pragma once
/// \file phantom_arm.hpp
/// The Phantom arm: joint encoders -> joint angles -> tip position, and tip force -> joint torques ->
/// DAC counts.
///
/// Kinematics: Cavusoglu, Feygin, Tendick, "A critical study of the mechanical and electrical properties
/// of the PHANToM haptic interface and improvements for high performance control" / "Kinematics and
/// dynamics of Phantom model 1.5 haptic interface" (UC Berkeley). With q1 the base yaw, q2 the pitch of
/// the first link and q3 the ABSOLUTE pitch of the second link (it is driven from the base through a
/// parallelogram, so its encoder measures theta_z relative to the base), the tip in the arm frame is
///   tip = [c1 (l1 c2 + l2 s3), s1 (l1 c2 + l2 s3), l1 s2 - l2 c3]
/// Because q3 is the motor's own coordinate, the motor torques are tau = J^T F with J = d tip / d q.
/// The relative elbow angle used by raw_omni (q3_rel = theta_z - home - q2) is `relative_elbow_angle`.
///
/// Frames: the arm frame has x along the arm at q1 = 0 (away from the writer), y to the writer's left,
/// z up. The device frame of haptic_device.hpp (x right, y away, z up) is the arm frame turned by -90
/// degrees about z, with its origin at the tip in the workspace-centre pose (choice, documented in
/// docs/devices.md).

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::phantom {

/// Joint angles [rad]: q1 base yaw, q2 first-link pitch, q3 second-link absolute pitch.
using JointAngles = Eigen::Vector3d;
/// Joint torques [N m], in the order of JointAngles.
using JointTorques = Eigen::Vector3d;

/// Link lengths [m].
struct ArmGeometry {
  double first_link_m = 0.0;   ///< l1 [m]
  double second_link_m = 0.0;  ///< l2 [m]

  /// Phantom Premium 1.5 (Cavusoglu et al.): l1 = 0.20955 m, l2 = 0.169545 m.
  [[nodiscard]] static ArmGeometry premium_1_5() noexcept { return {0.20955, 0.169545}; }
  /// Phantom Omni / Touch: about 0.135 m each (sources differ; calibrate for precise work).
  [[nodiscard]] static ArmGeometry omni() noexcept { return {0.135, 0.135}; }
};

/// Tip position [m] in the arm frame (Cavusoglu's formula above).
[[nodiscard]] Vec3 arm_frame_tip(const ArmGeometry& geometry, const JointAngles& q) noexcept;
/// d tip / d q [m/rad] in the arm frame; column j is the tip velocity per unit rate of joint j.
[[nodiscard]] Eigen::Matrix3d arm_frame_jacobian(const ArmGeometry& geometry, const JointAngles& q) noexcept;
/// raw_omni's relative elbow angle q3 - q2 [rad].
[[nodiscard]] inline double relative_elbow_angle(const JointAngles& q) noexcept { return q[2] - q[1]; }

/// The arm in device coordinates (haptic_device.hpp frame, origin at the workspace-centre tip).
class PhantomArm {
 public:
  /// `workspace_centre_rad`: the joint angles whose tip is the device origin.
  explicit PhantomArm(ArmGeometry geometry, JointAngles workspace_centre_rad = JointAngles::Zero()) noexcept;

  [[nodiscard]] const ArmGeometry& geometry() const noexcept { return geometry_; }
  /// Tip position [m], device frame.
  [[nodiscard]] Vec3 tip_position(const JointAngles& q) const noexcept;
  /// d tip_position / d q [m/rad], device frame.
  [[nodiscard]] Eigen::Matrix3d jacobian(const JointAngles& q) const noexcept;
  /// Joint torques [N m] that produce the tip force `force_n` [N, device frame]: J^T F.
  [[nodiscard]] JointTorques joint_torques(const JointAngles& q, const Vec3& force_n) const noexcept;

 private:
  ArmGeometry geometry_;
  Vec3 origin_in_arm_frame_;
};

/// Incremental encoders to joint angles. Encoders count from wherever the arm was at power-on, so the
/// angles are only meaningful after `home` (the stylus docked in the inkwell, a known pose).
class JointEncoders {
 public:
  /// `direction[j]` is +1 or -1: the sign of counts per positive joint angle.
  /// Throws InvalidArgument when counts_per_revolution <= 0 or a direction is not +-1.
  explicit JointEncoders(int counts_per_revolution = 15000, std::array<int, 3> direction = {1, 1, 1});

  /// Records that `counts` are read while the joints are at `home_rad` (the inkwell pose).
  void home(const std::array<std::int16_t, 3>& counts, const JointAngles& home_rad) noexcept;
  [[nodiscard]] bool is_homed() const noexcept { return homed_; }
  /// Joint angles [rad] for raw counts. The count difference from home is taken modulo 2^16, so the
  /// int16 wrap-around is harmless while a joint stays within about +-2 revolutions of home.
  [[nodiscard]] JointAngles angles(const std::array<std::int16_t, 3>& counts) const noexcept;
  /// Raw counts for joint angles [rad] (rounded to the nearest count; the inverse of `angles`).
  [[nodiscard]] std::array<std::int16_t, 3> counts(const JointAngles& q) const noexcept;
  /// Angle of one count [rad].
  [[nodiscard]] double radians_per_count() const noexcept;

 private:
  int counts_per_revolution_;
  std::array<int, 3> direction_;
  std::array<std::int16_t, 3> home_counts_{};
  JointAngles home_rad_ = JointAngles::Zero();
  bool homed_ = false;
};

/// Joint torque to DAC counts: tau_joint = gear_ratio * torque_constant * amps_per_count * counts.
/// The default values are PLACEHOLDERS of the right order of magnitude for an Omni (full scale about
/// 0.45 N m at the joint, i.e. 3.3 N at 0.135 m); they were not measured. Calibrate before trusting
/// force magnitudes on hardware.
struct MotorModel {
  Vec3 gear_ratio = Vec3::Constant(11.0);     ///< capstan ratio, joint turns per motor turn inverted [-]
  double torque_constant_n_m_per_a = 0.0259;  ///< motor torque constant [N m/A]
  double amps_per_dac_count = 0.00077;        ///< amplifier gain [A per DAC count]
  std::array<int, 3> direction = {1, 1, 1};   ///< sign of joint torque per positive count

  /// Joint torque [N m] of one DAC count on `joint`.
  [[nodiscard]] double newton_metres_per_count(int joint) const noexcept;
};

/// DAC counts for joint torques [N m]. When a joint would exceed the 12-bit range, all three are scaled
/// down by the same factor, so the direction of the torque vector (and of the tip force) is kept.
[[nodiscard]] std::array<std::int16_t, 3> torques_to_dac(const MotorModel& motors,
                                                         const JointTorques& tau) noexcept;
/// Joint torques [N m] for DAC counts.
[[nodiscard]] JointTorques dac_to_torques(const MotorModel& motors,
                                          const std::array<std::int16_t, 3>& counts) noexcept;

}  // namespace calligraphy::phantom
