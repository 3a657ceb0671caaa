#pragma once
/// \file guidance_law.hpp
/// Each guidance mode's own parameters (guidance_mode.hpp; docs/force-rendering.md, "Guidance modes"): one
/// struct per `GuidanceMode`, held by the force law as the variant `GuidanceLaw`, so that a mode carries
/// exactly the parameters it reads and no parameter waits unread for a mode it does not belong to.
#include <variant>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/render/guidance_mode.hpp"

namespace calligraphy {

/// `fixed`: the paper's virtual fixture, eq. (8); no parameter of its own.
struct FixedGuidance {
  bool operator==(const FixedGuidance&) const = default;
};

/// `fading`: eq. (8) scaled by a gain, set per repetition or from performance with `next_guidance_gain`.
struct FadingGuidance {
  double gain = 1.0;  ///< g in [0, 1] on F_et
  bool operator==(const FadingGuidance&) const = default;
};

/// Replay and timing: the spring towards the moving point pulls at most as hard as it does at this
/// distance [m], in (0, R_res]: K_et a d_max. The point may lead or trail the pen along the stroke by more
/// (a trainee slower than the teacher); the bound keeps the pull moderate and the force step small when a
/// pen held back that hard crosses the taper band at the edge of R_res.
inline constexpr double kDefaultMaxLeadM = 0.003;

/// `replay`: the attraction point follows a teacher's recorded pen in time.
struct ReplayGuidance {
  /// The teacher's recorded pen, device frame [m], times [s] non-decreasing (a recorded trial's trace:
  /// `TrialSample::time_s`, `position_m`). Read at renderer construction (teacher_replay.hpp).
  std::vector<TeacherSample> teacher_trajectory;
  double max_lead_m = kDefaultMaxLeadM;  ///< the pull's saturation distance [m], in (0, R_res]
  bool operator==(const ReplayGuidance&) const = default;
};

/// `assist_as_needed`: eq. (8) on the deviation beyond a band only, K_et a (d - b)+, continuous at the band
/// (set per repetition, or from performance with `next_assist_band`).
struct AssistAsNeededGuidance {
  double band_m = 0.001;  ///< half-width b [m] >= 0 of the slack band around the active element
  bool operator==(const AssistAsNeededGuidance&) const = default;
};

/// `error_amplification`: a bounded repulsive field g K_et a (X_p - X_S).
struct ErrorAmplificationGuidance {
  /// The repulsive stiffness as a share g in [0, 1] of K_et. Below the hand's stiffness the pen keeps an
  /// equilibrium on the stroke (0.25 x 400 = 100 N/m against the simulated relaxed hand's 150 N/m).
  double gain = 0.25;
  /// The repulsive force's bound [N] >= 0, so that a deviation is enlarged, never thrown: within the
  /// constraint space the field stores at most this force times R_res of energy.
  double max_force_n = 0.3;
  bool operator==(const ErrorAmplificationGuidance&) const = default;
};

/// `timing`: a minimum-jerk target along the stroke, pulled towards along the stroke only.
struct TimingGuidance {
  /// The target's mean speed [m/s] > 0 along each stroke (the stroke's length over its duration).
  /// Default: a fluent writer's pace (the simulated skilled writer's, docs/writer.md).
  double speed_m_s = 0.04;
  double max_lead_m = kDefaultMaxLeadM;  ///< the pull's saturation distance [m], in (0, R_res]
  bool operator==(const TimingGuidance&) const = default;
};

// Each law's table (parameter_table.hpp): the one definition of its fields' ranges, units and docs.
// A moving target's max_lead_m is also at most the force law's constraint_radius_m, a rule across
// structs that `validate_guidance_law` adds.
template <>
struct ParameterTable<FixedGuidance> {
  static constexpr std::string_view name = "FixedGuidance";
  [[nodiscard]] static std::span<const ParameterField<FixedGuidance>> fields() noexcept { return {}; }
};
template <>
struct ParameterTable<FadingGuidance> {
  static constexpr std::string_view name = "FadingGuidance";
  [[nodiscard]] static std::span<const ParameterField<FadingGuidance>> fields() noexcept;
};
template <>
struct ParameterTable<ReplayGuidance> {
  static constexpr std::string_view name = "ReplayGuidance";
  [[nodiscard]] static std::span<const ParameterField<ReplayGuidance>> fields() noexcept;
};
template <>
struct ParameterTable<AssistAsNeededGuidance> {
  static constexpr std::string_view name = "AssistAsNeededGuidance";
  [[nodiscard]] static std::span<const ParameterField<AssistAsNeededGuidance>> fields() noexcept;
};
template <>
struct ParameterTable<ErrorAmplificationGuidance> {
  static constexpr std::string_view name = "ErrorAmplificationGuidance";
  [[nodiscard]] static std::span<const ParameterField<ErrorAmplificationGuidance>> fields() noexcept;
};
template <>
struct ParameterTable<TimingGuidance> {
  static constexpr std::string_view name = "TimingGuidance";
  [[nodiscard]] static std::span<const ParameterField<TimingGuidance>> fields() noexcept;
};

/// How F_et attracts, with the mode's own parameters. The alternatives are in `GuidanceMode` order.
using GuidanceLaw = std::variant<FixedGuidance, FadingGuidance, ReplayGuidance, AssistAsNeededGuidance,
                                 ErrorAmplificationGuidance, TimingGuidance>;

/// The mode `law` is a law of.
[[nodiscard]] GuidanceMode mode_of(const GuidanceLaw& law) noexcept;

/// The law of `mode` with its default parameters (a replay with no teacher yet).
[[nodiscard]] GuidanceLaw default_guidance_law(GuidanceMode mode);

/// Throws InvalidArgument naming the field (e.g. "FadingGuidance.gain"), its value and range when a value
/// is out of range or not finite (the law's `ParameterTable`); a replay's teacher is checked by
/// `validate_teacher_trajectory`. The moving targets' max_lead_m must be within `constraint_radius_m` [m].
void validate_guidance_law(const GuidanceLaw& law, double constraint_radius_m);

}  // namespace calligraphy
