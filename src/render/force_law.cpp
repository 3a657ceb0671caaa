#include "calligraphy/render/force_law.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

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
  check(constraint_taper_m, "constraint_taper_m", false);
  check(crossfade_s, "crossfade_s", false);
  check(paper_fade_s, "paper_fade_s", false);
  acceptance.validate();
  check(paper_damping_n_s_per_m, "paper_damping_n_s_per_m", false);
  check(max_foot_speed_m_s, "max_foot_speed_m_s", true);
  check(friction_coefficient, "friction_coefficient", false);
  check(friction_stick_speed_m_s, "friction_stick_speed_m_s", true);
  check(off_stroke_force_n, "off_stroke_force_n", false);
  check(off_stroke_travel_m, "off_stroke_travel_m", true);
  check(off_stroke_damping_n_s_per_m, "off_stroke_damping_n_s_per_m", false);
  check(off_stroke_speed_m_s, "off_stroke_speed_m_s", true);
  check(off_stroke_velocity_cutoff_hz, "off_stroke_velocity_cutoff_hz", true);
  // A replay's or timing target's attraction point must stay within R_res of the pen.
  validate_guidance_law(guidance_law, constraint_radius_m);
  if (constraint_taper_m > constraint_radius_m) {
    throw InvalidArgument("ForceLawParameters.constraint_taper_m = " + std::to_string(constraint_taper_m) +
                          " must not exceed constraint_radius_m = " + std::to_string(constraint_radius_m));
  }
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

Vec2 friction_force(const Vec2& velocity_m_s, double normal_force_n, double coefficient,
                    double stick_speed_m_s) noexcept {
  const double speed = velocity_m_s.norm();
  const double limit = coefficient * std::max(normal_force_n, 0.0);
  if (!(stick_speed_m_s > 0.0) || speed == 0.0) return Vec2::Zero();
  return speed > stick_speed_m_s ? Vec2(-limit / speed * velocity_m_s)
                                 : Vec2(-limit / stick_speed_m_s * velocity_m_s);
}

double constraint_taper(double distance_m, double radius_m, double band_m) noexcept {
  if (distance_m >= radius_m) return 0.0;
  if (band_m <= 0.0 || distance_m <= radius_m - band_m) return 1.0;
  const double u = (radius_m - distance_m) / band_m;  // 0 at the edge, 1 at the inner side of the band
  return u * u * (3.0 - 2.0 * u);
}

Vec2 off_stroke_friction(const Vec2& tip_m, Vec2& anchor_m, double force_n, double travel_m) noexcept {
  if (!(travel_m > 0.0)) return Vec2::Zero();
  const Vec2 stretch = tip_m - anchor_m;
  const double length = stretch.norm();
  if (length > travel_m) anchor_m = tip_m - stretch * (travel_m / length);  // the pen drags the point along
  return (force_n / travel_m) * (anchor_m - tip_m);
}

Vec2 off_stroke_resistance(const Vec2& velocity_m_s, double damping_n_s_per_m,
                           double threshold_speed_m_s) noexcept {
  if (!(threshold_speed_m_s > 0.0)) return Vec2::Zero();
  const double u = std::clamp(velocity_m_s.norm() / threshold_speed_m_s - 1.0, 0.0, 1.0);
  return -damping_n_s_per_m * u * u * (3.0 - 2.0 * u) * velocity_m_s;
}

Vec3 clamp_force(const Vec3& force_n, double max_force_n) noexcept {
  if (!force_n.allFinite() || !(max_force_n > 0.0)) return Vec3::Zero();
  const double magnitude = force_n.norm();
  return magnitude > max_force_n ? Vec3(force_n * (max_force_n / magnitude)) : force_n;
}

}  // namespace calligraphy
