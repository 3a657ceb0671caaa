#include "calligraphy/render/force_law.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"

namespace calligraphy {

namespace {

using Field = ParameterField<ForceLawParameters>;
using P = ForceLawParameters;
// The force law's lengths: at most 0.1 m, more than the side of a character (60 mm, SceneLayout) and about
// twenty times the paper's constraint radius (a few mm, section 4.3): a larger one is a typing error, and a
// bound keeps every product with a stiffness finite.
constexpr ParameterRange kLength{.high = 0.1};
constexpr ParameterRange kPositiveLength{.high = 0.1, .low_open = true};
// Its fade times: at most 10 s, longer than a stroke of a 60 mm character takes to write, so a longer fade
// never completes within the stroke it starts on.
constexpr ParameterRange kFadeTime{.high = 10.0};

// In declaration order; the docs say what the value is, the header says why.
constexpr std::array kFields{
    Field{"guidance_stiffness_n_per_m", "N/m", kNonNegativeRange, "K_et per unit attraction factor (eq. 8)",
          &P::guidance_stiffness_n_per_m},
    Field{"paper_stiffness_n_per_m", "N/m", kNonNegativeRange, "K_en, stiffness of the virtual paper (eq. 9)",
          &P::paper_stiffness_n_per_m},
    Field{"constraint_radius_m", "m", kPositiveLength,
          "R_res, radius of the constraint space around the active element (section 4.3)",
          &P::constraint_radius_m},
    Field{"resistance_damping_n_s_per_m", "N s/m", kNonNegativeRange,
          "damping against writing backwards along the active element (Fig. 4)",
          &P::resistance_damping_n_s_per_m},
    Field{"contact_hysteresis_m", "m", kLength,
          "height above the paper at which a touching tip counts as lifted (section 6)",
          &P::contact_hysteresis_m},
    Field{"off_stroke_force_n", "N", kNonNegativeRange,
          "friction against writing away from the active stroke in CS; 0 = the paper's CS",
          &P::off_stroke_force_n},
    Field{"off_stroke_travel_m", "m", kPositiveLength,
          "travel before the off-stroke friction reaches its force", &P::off_stroke_travel_m},
    Field{"off_stroke_damping_n_s_per_m", "N s/m", kNonNegativeRange,
          "damping of motion away from the active element in WS outside R_res",
          &P::off_stroke_damping_n_s_per_m},
    Field{"off_stroke_speed_m_s", "m/s", kPositiveRange, "speed below which that damping fades out",
          &P::off_stroke_speed_m_s},
    Field{"off_stroke_velocity_cutoff_hz", "Hz", kPositiveRange,
          "low-pass on the velocity the off-stroke damping reads", &P::off_stroke_velocity_cutoff_hz},
    Field{"constraint_taper_m", "m", kLength,
          "band at R_res over which F_et tapers to zero, at most R_res; 0 = the paper's step",
          &P::constraint_taper_m},
    Field{"crossfade_s", "s", kFadeTime,
          "cross-fade time of the in-plane force when the active element or state changes; 0 = off",
          &P::crossfade_s},
    Field{"paper_fade_s", "s", kFadeTime,
          "fade time of the paper force when it starts or stops pushing (AS <-> CS); 0 = off",
          &P::paper_fade_s},
    Field{"paper_damping_n_s_per_m", "N s/m", kNonNegativeRange,
          "damping of the paper on inward motion only; 0 = off", &P::paper_damping_n_s_per_m},
    Field{"max_foot_speed_m_s", "m/s", kPositiveRange, "highest speed of the rendered attraction target X_S",
          &P::max_foot_speed_m_s},
    Field{"friction_coefficient", "", kNonNegativeRange,
          "Coulomb friction coefficient mu of the paper (not in the paper), dimensionless",
          &P::friction_coefficient},
    Field{"friction_stick_speed_m_s", "m/s", kPositiveRange, "stick band of the friction, viscous below it",
          &P::friction_stick_speed_m_s},
};

}  // namespace

std::span<const ParameterField<ForceLawParameters>> ParameterTable<ForceLawParameters>::fields() noexcept {
  return kFields;
}

void ForceLawParameters::validate() const {
  check_parameters(*this);
  acceptance.validate();
  // A replay's or timing target's attraction point must stay within R_res of the pen.
  validate_guidance_law(guidance_law, constraint_radius_m);
  if (constraint_taper_m > constraint_radius_m) {
    throw InvalidArgument("ForceLawParameters.constraint_taper_m = " + shortest_decimal(constraint_taper_m) +
                          " must not exceed constraint_radius_m = " + shortest_decimal(constraint_radius_m));
  }
  if (!kForceLawNearestToleranceRange.contains(nearest.tolerance)) {
    throw InvalidArgument("ForceLawParameters.nearest.tolerance = " + shortest_decimal(nearest.tolerance) +
                          " is out of range: expected " + kForceLawNearestToleranceRange.text());
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

// The devices' clamp: a finite force whose squared magnitude overflows (1e308 N) is scaled, never zeroed.
Vec3 clamp_force(const Vec3& force_n, double max_force_n) noexcept {
  return clamp_force_magnitude(force_n, max_force_n);
}

}  // namespace calligraphy
