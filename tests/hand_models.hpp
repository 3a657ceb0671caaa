#pragma once
// Hand models for the stability tests: the hand holding the simulated device's stylus. The relaxed
// and stiff hands (a relaxed grip 150 N/m, 3 N s/m; a stiff grip 600 N/m, 8 N s/m) are assumed,
// order-of-magnitude figures, not measured on people. Test helpers, not library API.
#include "calligraphy/devices/simulated_device.hpp"

namespace calligraphy::testing {

/// A hand as a spring and damper pulling the stylus towards a fixed target: F = k (x_d - x) - b v.
class ImpedanceHand final : public HandModel {
 public:
  ImpedanceHand(double stiffness_n_per_m, double damping_n_s_per_m, const Vec3& target_m)
      : k_(stiffness_n_per_m), b_(damping_n_s_per_m), target_(target_m) {}
  Vec3 hand_force(double, const Vec3& position_m, const Vec3& velocity_m_s) override {
    return k_ * (target_ - position_m) - b_ * velocity_m_s;
  }

 private:
  double k_;
  double b_;
  Vec3 target_;
};

/// A relaxed hand pressing towards `target_m` (150 N/m, 3 N s/m).
inline ImpedanceHand relaxed_hand(const Vec3& target_m) { return ImpedanceHand(150.0, 3.0, target_m); }
/// A stiff hand pressing towards `target_m` (600 N/m, 8 N s/m).
inline ImpedanceHand stiff_hand(const Vec3& target_m) { return ImpedanceHand(600.0, 8.0, target_m); }

/// No hand: nothing holds the stylus, which only carries a constant load of `load_n` into the paper
/// (-z), a weight resting on it. No stiffness, no damping: the device's own damping is all there is,
/// the case Colgate's bound is about.
class NoHand final : public HandModel {
 public:
  explicit NoHand(double load_n) : load_n_(load_n) {}
  Vec3 hand_force(double, const Vec3&, const Vec3&) override { return Vec3(0.0, 0.0, -load_n_); }

 private:
  double load_n_;
};

}  // namespace calligraphy::testing
