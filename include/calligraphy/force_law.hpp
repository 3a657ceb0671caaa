#pragma once
/// \file force_law.hpp
/// The force model of paper section 5: F_e = F_en + F_et (eq. 7). Free functions, SI units, servo path
/// (noexcept, no allocation). Device frame: the paper is z = z0, +z out of the paper.
#include "calligraphy/geometry.hpp"
#include "calligraphy/nearest_point.hpp"

namespace calligraphy {

/// Parameters of the force law. Validated by `validate` (throws InvalidArgument naming the field).
struct ForceLawParameters {
  /// K_et per unit attraction factor (eq. 8) [N/m]: the guidance stiffness of the virtual fixture.
  double guidance_stiffness_n_per_m = 400.0;
  /// K_en, stiffness of the virtual paper (eq. 9) [N/m].
  double paper_stiffness_n_per_m = 800.0;
  /// Radius of the constraint space R_res around the active element [m] (section 4.3).
  double constraint_radius_m = 0.006;
  /// Damping against moving backwards along the active element (internal sequence, Fig. 4) [N s/m].
  double resistance_damping_n_s_per_m = 15.0;
  /// Contact hysteresis [m]: once touching, the tip counts as lifted only when it is this far above the
  /// paper, so that the bounce of a touch-down does not chatter between SS and WS (section 6).
  double contact_hysteresis_m = 0.0005;
  /// In-plane guidance on (F_et and the resistance force); the paper force is always rendered.
  bool guidance = true;
  /// How the foot point X_S on curve elements is found.
  NearestPointOptions nearest{};

  /// Throws InvalidArgument when a value is negative, not finite, or the radius is not positive.
  void validate() const;
};

/// Eq. (9), written to push out of the paper: K_en (z0 - z) e_z when the tip is below the paper
/// (z < z0), else zero [N].
[[nodiscard]] Vec3 paper_force(double tip_z_m, double paper_z_m, double stiffness_n_per_m) noexcept;

/// Eq. (8) with the attracting sign: K_et a (X_S - X_p) [N], in the paper plane. As printed the paper's
/// K_et (X_p - X_S) would push the tip away from the stroke (REFERENCE.md section 1).
[[nodiscard]] Vec2 attraction_force(const Vec2& tip_m, const Vec2& foot_m, double stiffness_n_per_m,
                                    double attraction_factor) noexcept;

/// Resistance against writing backwards (section 2.2, Fig. 4): -b (v . t) t when v . t < 0, else zero
/// [N]; `tangent` is the unit writing direction of the active element at the foot point.
[[nodiscard]] Vec2 resistance_force(const Vec2& velocity_m_s, const Vec2& tangent, double damping_n_s_per_m) noexcept;

/// Scales `force` down to at most `max_force_n`, keeping its direction; a non-finite force gives zero.
[[nodiscard]] Vec3 clamp_force(const Vec3& force_n, double max_force_n) noexcept;

}  // namespace calligraphy
