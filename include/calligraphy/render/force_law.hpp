#pragma once
/// \file force_law.hpp
/// The force model of paper section 5: F_e = F_en + F_et (eq. 7). Free functions, SI units, servo path
/// (noexcept, no allocation). Device frame: the paper is z = z0, +z out of the paper.
#include "calligraphy/core/geometry.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/render/guidance_law.hpp"

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
  /// In-plane guidance on (F_et, the resistance force and the off-stroke resistance); the paper force is
  /// always rendered.
  bool guidance = true;

  /// How F_et attracts, with the mode's own parameters (guidance_law.hpp): the paper's fixed fixture by
  /// default, or a fading, replay, assist-as-needed, error-amplification or timing law.
  GuidanceLaw guidance_law{};

  // Off-stroke resistance (docs/force-rendering.md): under guidance, writing off the active stroke is
  // felt. The paper's resistance of Fig. 4 extended from the direction within a stroke to the order of
  // the strokes (section 2.2; section 6: the active stroke masks the others). Both parts 0 = the
  // paper (CS: normal force only; WS: no in-plane force outside R_res).
  /// In CS (touching inside the active character's box, not writing the active stroke: a stroke out
  /// of order, a stroke started from its end, a stroke continued after a lift), a friction of this
  /// force [N] >= 0 against in-plane motion, rendered with an adhesion point (Hayward & Armstrong
  /// 2000): a spring to a point that the pen drags along once it is `off_stroke_travel_m` away, so the
  /// force is the same at any speed and the pen at rest is simply held.
  double off_stroke_force_n = 0.5;
  /// Travel [m] > 0 before the off-stroke friction reaches its force (spring off_stroke_force_n /
  /// off_stroke_travel_m: 500 N/m by default, below Colgate's bound at 1 kHz and more).
  double off_stroke_travel_m = 0.001;
  /// In WS outside the constraint space, a damper [N s/m] >= 0 on the part of the in-plane velocity
  /// that leads away from the active element (a stroke that set off from the active start in another
  /// direction), never on coming back to it.
  double off_stroke_damping_n_s_per_m = 25.0;
  /// Speed [m/s] > 0 below which that damper is off; it ramps in (smoothstep) up to twice this speed,
  /// so that a pen at rest or creeping feels only the paper.
  double off_stroke_speed_m_s = 0.005;
  /// Cut-off [Hz] > 0 of the first-order low-pass on the velocity the damper acts on, so that encoder
  /// noise in the velocity (one 23 um quantum at 1 kHz is a 23 mm/s spike) does not come through it
  /// as force steps. Not lower: above the cut-off a low-passed damper B / (1 + s / w_c) acts like a
  /// spring B w_c on the pen's mass (at 10 Hz and 40 N s/m a 2.5 kN/m spring, which rang at about
  /// 20 Hz on the simulated device); at 30 Hz and 25 N s/m the pen with a relaxed hand keeps a damping
  /// ratio of about 0.6.
  double off_stroke_velocity_cutoff_hz = 30.0;

  // Smoothness (paper section 6, sources of instability; docs/force-rendering.md).
  /// Band at the edge of the constraint space over which F_et tapers to zero [m], in [0, R_res]: F_et
  /// is scaled by a smoothstep of (R_res - d) / band, so it is continuous at R_res instead of stepping
  /// by K_et a R_res. 0 = the paper's step.
  double constraint_taper_m = 0.002;
  /// Cross-fade time [s] of the in-plane force when the active element, stroke or character changes,
  /// when WS is entered or left, or when the tip enters or leaves the constraint space. 0 = off.
  double crossfade_s = 0.05;
  /// Time [s] over which the paper force fades in when the paper starts to push (AS/SS -> CS/WS) and
  /// out when it stops (CS -> AS). 0 = off.
  double paper_fade_s = 0.2;
  /// When the pen has gone round a corner and when a stroke is written (stroke_progress.hpp): progress
  /// along the stroke's centre line within a corridor, ends short or past within a tolerance.
  StrokeAcceptance acceptance{};
  /// Damping of the paper on inward motion only (v_z < 0, below the paper) [N s/m]. Colgate's bound
  /// shrinks by it: K <= 2 (b - B) / T. 0 = off.
  double paper_damping_n_s_per_m = 0.0;
  /// Highest speed of the rendered foot point X_S [m/s]: the attraction target moves towards the
  /// tracked foot point at most this fast, so a jump of the nearest point does not step the force.
  double max_foot_speed_m_s = 0.3;
  /// Coulomb friction coefficient mu of the paper (not in the paper), dimensionless: |F_f| = mu N.
  double friction_coefficient = 0.15;
  /// Stick band [m/s] > 0: below this in-plane speed friction is viscous, mu N v / v_band, which
  /// avoids the chatter of a sign function at rest.
  double friction_stick_speed_m_s = 0.02;
  /// How the foot point X_S on curve elements is found.
  NearestPointOptions nearest{};

  /// Throws InvalidArgument naming the field when a numeric value is outside its table's range
  /// (`ParameterTable<ForceLawParameters>`: not finite, negative, or zero where it must be positive), the
  /// acceptance is invalid, the guidance law's parameters are out of range (validate_guidance_law), or the
  /// taper band is wider than the radius.
  void validate() const;
};

/// The numeric fields of ForceLawParameters (parameter_table.hpp): the one definition of their units and
/// ranges. Not in it: `guidance`, `guidance_law` (its own tables), `acceptance` and `nearest` (their own
/// validation).
template <>
struct ParameterTable<ForceLawParameters> {
  static constexpr std::string_view name = "ForceLawParameters";
  [[nodiscard]] static std::span<const ParameterField<ForceLawParameters>> fields() noexcept;
};

/// Eq. (9), written to push out of the paper: K_en (z0 - z) e_z when the tip is below the paper
/// (z < z0), else zero [N].
[[nodiscard]] Vec3 paper_force(double tip_z_m, double paper_z_m, double stiffness_n_per_m) noexcept;

/// Eq. (8) with the attracting sign: K_et a (X_S - X_p) [N], in the paper plane. As printed the paper's
/// K_et (X_p - X_S) would push the tip away from the stroke (Wang, Zhang & Yao 2006, section 5).
[[nodiscard]] Vec2 attraction_force(const Vec2& tip_m, const Vec2& foot_m, double stiffness_n_per_m,
                                    double attraction_factor) noexcept;

/// Resistance against writing backwards (section 2.2, Fig. 4): -b (v . t) t when v . t < 0, else zero
/// [N]; `tangent` is the unit writing direction of the active element at the foot point.
[[nodiscard]] Vec2 resistance_force(const Vec2& velocity_m_s, const Vec2& tangent,
                                    double damping_n_s_per_m) noexcept;

/// Paper friction (Coulomb with a stick band): -mu N v / |v| when |v| > v_band, else -mu N v / v_band
/// [N], in the paper plane; `normal_force_n` N >= 0 [N], in-plane velocity [m/s].
[[nodiscard]] Vec2 friction_force(const Vec2& velocity_m_s, double normal_force_n, double coefficient,
                                  double stick_speed_m_s) noexcept;

/// Taper of F_et at the constraint-space edge, in [0, 1]: 1 when distance <= R - band, 0 when
/// distance >= R, a smoothstep between; band 0 gives the step 1 -> 0 at R. Lengths [m].
[[nodiscard]] double constraint_taper(double distance_m, double radius_m, double band_m) noexcept;

/// Off-stroke friction with an adhesion point (Hayward & Armstrong 2000): moves `anchor_m` towards the
/// tip until it is at most `travel_m` away, and returns the spring force (force_n / travel_m) (anchor -
/// tip) [N], at most force_n. Lengths [m], force [N]; travel_m > 0.
[[nodiscard]] Vec2 off_stroke_friction(const Vec2& tip_m, Vec2& anchor_m, double force_n,
                                       double travel_m) noexcept;

/// Off-stroke damper: -B v w(|v|) [N] in the paper plane, w a smoothstep from 0 at |v| = v0 to 1 at
/// 2 v0; in-plane velocity [m/s], B [N s/m], v0 [m/s] > 0.
[[nodiscard]] Vec2 off_stroke_resistance(const Vec2& velocity_m_s, double damping_n_s_per_m,
                                         double threshold_speed_m_s) noexcept;

/// Scales `force` down to at most `max_force_n`, keeping its direction; a non-finite force or a non-positive
/// limit gives zero, and a finite force of any size (1e308 N) is scaled, never zeroed (clamp_force_magnitude,
/// core/force_limits.hpp).
[[nodiscard]] Vec3 clamp_force(const Vec3& force_n, double max_force_n) noexcept;

}  // namespace calligraphy
