#include "calligraphy/force_law.hpp"

#include <cmath>
#include <string>

#include "calligraphy/errors.hpp"

namespace calligraphy {

void ForceLawParameters::validate() const {
  const auto check = [](double value, const char* name, bool positive) {
    if (!std::isfinite(value) || value < 0.0 || (positive && value == 0.0)) {
      throw InvalidArgument(std::string("ForceLawParameters.") + name + " = " + std::to_string(value) +
                            (positive ? " must be finite and > 0" : " must be finite and >= 0"));
    }
  };
  check(guidance_stiffness_n_per_m, "guidance_stiffness_n_per_m", false);
  check(paper_stiffness_n_per_m, "paper_stiffness_n_per_m", false);
  check(constraint_radius_m, "constraint_radius_m", true);
  check(resistance_damping_n_s_per_m, "resistance_damping_n_s_per_m", false);
  check(contact_hysteresis_m, "contact_hysteresis_m", false);
}

Vec3 paper_force(double tip_z_m, double paper_z_m, double stiffness_n_per_m) noexcept {
  const double depth = paper_z_m - tip_z_m;
  return depth > 0.0 ? Vec3(0.0, 0.0, stiffness_n_per_m * depth) : Vec3::Zero();
}

Vec2 attraction_force(const Vec2& tip_m, const Vec2& foot_m, double stiffness_n_per_m,
                      double attraction_factor) noexcept {
  return stiffness_n_per_m * attraction_factor * (foot_m - tip_m);
}

Vec2 resistance_force(const Vec2& velocity_m_s, const Vec2& tangent, double damping_n_s_per_m) noexcept {
  const double along = velocity_m_s.dot(tangent);
  return along < 0.0 ? Vec2(-damping_n_s_per_m * along * tangent) : Vec2(Vec2::Zero());
}

Vec3 clamp_force(const Vec3& force_n, double max_force_n) noexcept {
  if (!force_n.allFinite() || !(max_force_n > 0.0)) return Vec3::Zero();
  const double magnitude = force_n.norm();
  return magnitude > max_force_n ? Vec3(force_n * (max_force_n / magnitude)) : force_n;
}

}  // namespace calligraphy
