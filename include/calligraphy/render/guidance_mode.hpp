#pragma once
/// \file guidance_mode.hpp
/// How the in-plane guidance of the renderer attracts the pen (docs/force-rendering.md, "Guidance modes"):
///  - `fixed`: the paper's virtual fixture, eq. (8): K_et a (X_S - X_p) towards the foot point X_S on the
///    active element (Wang, Zhang & Yao 2006, section 5).
///  - `fading`: the same attraction scaled by a gain g in [0, 1], set per repetition or from performance
///    with `next_guidance_gain` (fading guidance: Marchal-Crespo & Reinkensmeyer 2008, 2009, 2010).
///  - `replay`: a recorded trial of a teacher becomes time-indexed guidance: the attraction point moves
///    along the teacher's pen path at the teacher's pace ("record and replay": Henmi & Yoshikawa 1998,
///    Feygin, Keehner & Tendick 2002). The clock of stroke k starts when the pen enters WS on it.
///  - `assist_as_needed`: the fixture's spring acts only on the deviation beyond a band around the stroke,
///    K_et a (d - b)+, so errors within the band are the writer's own to correct; the band b widens as the
///    writer's error falls and narrows as it grows (`next_assist_band`): assist-as-needed (Emken, Bobrow &
///    Reinkensmeyer 2005; Banala et al. 2009, a force tunnel around the path).
///  - `error_amplification`: a bounded repulsive field that enlarges the deviation, g K_et a (X_p - X_S),
///    at most `ErrorAmplificationGuidance::max_force_n` (error augmentation: Emken & Reinkensmeyer 2005;
///    Patton et al. 2006).
///  - `timing`: a target moves along the stroke's centre line at a minimum-jerk pace (Flash & Hogan 1985)
///    and the pen is pulled towards it along the stroke only, never across it: guidance on timing, not on
///    shape.
/// Skill-adaptive selection (Milot et al. 2010: guidance for the less skilled, amplification for the
/// more skilled) chooses one of these per repetition: `skill_adaptive_mode`.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/core/schema.hpp"

namespace calligraphy {

enum class GuidanceMode : std::uint8_t {
  fixed,                ///< eq. (8) as printed (with the attracting sign): the paper's virtual fixture
  fading,               ///< eq. (8) scaled by FadingGuidance::gain in [0, 1]
  replay,               ///< the attraction point follows ReplayGuidance::teacher_trajectory in time
  assist_as_needed,     ///< eq. (8) on the deviation beyond AssistAsNeededGuidance::band_m only
  error_amplification,  ///< a bounded repulsive field, ErrorAmplificationGuidance::gain x eq. (8)
  timing,               ///< a minimum-jerk target along the stroke, pulled towards along the stroke only
};

/// The one spelling of each mode, in every file, option and Python argument.
template <>
struct EnumTable<GuidanceMode> {
  static constexpr std::string_view name = "GuidanceMode";
  static constexpr std::array<EnumEntry<GuidanceMode>, 6> entries{{
      {GuidanceMode::fixed, "fixed", "the paper's virtual fixture, eq. (8)"},
      {GuidanceMode::fading, "fading", "the fixture scaled by a gain in [0, 1]"},
      {GuidanceMode::replay, "replay", "the attraction point follows a teacher's recording in time"},
      {GuidanceMode::assist_as_needed, "assist-as-needed", "the fixture on the deviation beyond a band only"},
      {GuidanceMode::error_amplification, "error-amplification", "a bounded field pushing off the stroke"},
      {GuidanceMode::timing, "timing",
       "a minimum-jerk target along the stroke, pulled towards along it only"},
  }};
};

/// "fixed", "fading", "replay", "assist-as-needed", "error-amplification" or "timing" (EnumTable).
const char* to_string(GuidanceMode mode) noexcept;
/// Every mode, in declaration order.
[[nodiscard]] std::span<const GuidanceMode> guidance_modes() noexcept;
/// The names of every mode joined by '|' ("fixed|fading|..."), for help texts and errors.
[[nodiscard]] const char* guidance_mode_names() noexcept;
/// The mode called `name` (as `to_string` spells it); nullopt for any other name.
std::optional<GuidanceMode> guidance_mode_from_string(std::string_view name) noexcept;

/// One sample of a teacher's recorded pen: time [s] and position in the device frame [m] (the scene's
/// frame: the paper is z = paper_z_m, +z out of it). A `TrialSample`'s time_s and position_m.
struct TeacherSample {
  double time_s = 0.0;
  Vec3 position_m = Vec3::Zero();
  friend bool operator==(const TeacherSample& a, const TeacherSample& b) {
    return a.time_s == b.time_s && a.position_m == b.position_m;
  }
};

/// Throws InvalidArgument naming the first sample whose time or position is not finite or whose time
/// is below the previous one's, or when there are fewer than 2 samples.
void validate_teacher_trajectory(std::span<const TeacherSample> samples);

/// The performance-based fading rule: g(n+1) = clamp(f g(n) + k e(n), 0, 1), a forgetting factor f that
/// fades the guidance when the trainee does well and an error gain k that brings it back when the error
/// e grows: the error-based controller with a forgetting factor of Emken, Benitez & Reinkensmeyer 2007
/// (J NeuroEng Rehabil 4:8), applied once per repetition.
struct FadingRule {
  double forgetting_factor = 0.8;   ///< f in [0, 1]
  double error_gain_per_m = 200.0;  ///< k [1/m] in [0, 10^6]: 1 mm of mean deviation adds 0.2 to the gain
  /// Throws InvalidArgument naming the field when a value is out of range or not finite (its table).
  void validate() const;
  bool operator==(const FadingRule&) const = default;
};

/// The next repetition's gain from this repetition's gain g(n) in [0, 1] and error e(n) >= 0 [m] (for
/// example the mean deviation of the trial). Throws InvalidArgument for a gain outside [0, 1], a
/// negative or non-finite error, or a bad rule.
[[nodiscard]] double next_guidance_gain(double gain, double error_m, const FadingRule& rule = {});

/// The assist-as-needed band rule: b(n+1) = clamp(b(n) + k (e* - e(n)), b_min, b_max). An error e below
/// the target e* widens the band (less help), above it narrows it (more help): the error-based adaptation
/// of assistance of Emken, Bobrow & Reinkensmeyer (2005, Proc. IEEE ICORR) applied to the width of a
/// force tunnel (Banala et al. 2009, IEEE TNSRE 17:2), once per repetition.
struct AssistBandRule {
  double target_error_m = 0.0015;  ///< e* [m] in (0, 0.1]: the deviation the band adapts towards
  double rate = 1.0;          ///< k in [0, 100] (dimensionless): 1 mm of error below e* widens the band 1 mm
  double min_band_m = 0.0;    ///< b_min [m] in [0, 0.1]
  double max_band_m = 0.004;  ///< b_max [m] in [b_min, 0.1]
  /// Throws InvalidArgument naming the field when a value is out of range or not finite (its table), or
  /// when max_band_m < min_band_m.
  void validate() const;
  bool operator==(const AssistBandRule&) const = default;
};

/// The next repetition's band [m] from this repetition's band b(n) >= 0 and error e(n) >= 0 [m]. Throws
/// InvalidArgument for a negative or non-finite band or error, or a bad rule.
[[nodiscard]] double next_assist_band(double band_m, double error_m, const AssistBandRule& rule = {});

/// Skill-adaptive selection (Milot, Marchal-Crespo, Green, Cramer & Reinkensmeyer 2010, Exp Brain Res
/// 201:119: haptic guidance helped the less skilled learn, error amplification the more skilled).
struct SkillAdaptiveRule {
  /// Error [m] in (0, 0.1] at or above which the writer counts as less skilled and is guided.
  double threshold_m = 0.002;
  /// Throws InvalidArgument naming the field when the threshold is outside its table's range.
  void validate() const;
  bool operator==(const SkillAdaptiveRule&) const = default;
};

/// The mode of the next repetition from the error of the previous one [m] >= 0 (NaN: no stroke written,
/// the least skilled): `fixed` when the error is at or above the threshold, else `error_amplification`.
/// Throws InvalidArgument for a negative or infinite error or a bad rule.
[[nodiscard]] GuidanceMode skill_adaptive_mode(double previous_error_m, const SkillAdaptiveRule& rule = {});

// Each rule's table (parameter_table.hpp): the one definition of its fields' ranges, which its validate(),
// a protocol's guidance "parameters" and a trial record read. A length beyond 0.1 m (the 60 mm character box
// and more) means nothing here.
template <>
struct ParameterTable<FadingRule> {
  static constexpr std::string_view name = "FadingRule";
  [[nodiscard]] static std::span<const ParameterField<FadingRule>> fields() noexcept;
};
template <>
struct ParameterTable<AssistBandRule> {
  static constexpr std::string_view name = "AssistBandRule";
  [[nodiscard]] static std::span<const ParameterField<AssistBandRule>> fields() noexcept;
};
template <>
struct ParameterTable<SkillAdaptiveRule> {
  static constexpr std::string_view name = "SkillAdaptiveRule";
  [[nodiscard]] static std::span<const ParameterField<SkillAdaptiveRule>> fields() noexcept;
};

}  // namespace calligraphy
