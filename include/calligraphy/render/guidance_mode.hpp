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
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

enum class GuidanceMode : std::uint8_t {
  fixed,   ///< eq. (8) as printed (with the attracting sign): the paper's virtual fixture
  fading,  ///< eq. (8) scaled by ForceLawParameters::guidance_gain in [0, 1]
  replay,  ///< the attraction point follows ForceLawParameters::teacher_trajectory in time
};

/// "fixed", "fading" or "replay".
const char* to_string(GuidanceMode mode) noexcept;
/// The mode called `name` ("fixed", "fading", "replay"); nullopt for any other name.
std::optional<GuidanceMode> guidance_mode_from_string(std::string_view name) noexcept;

/// One sample of a teacher's recorded pen: time [s] and position in the device frame [m] (the scene's
/// frame: the paper is z = paper_z_m, +z out of it). A `TrialSample`'s time_s and position_m.
struct TeacherSample {
  double time_s = 0.0;
  Vec3 position_m = Vec3::Zero();
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
  double error_gain_per_m = 200.0;  ///< k [1/m], >= 0: 1 mm of mean deviation adds 0.2 to the gain
  /// Throws InvalidArgument naming the field when a value is out of range or not finite.
  void validate() const;
};

/// The next repetition's gain from this repetition's gain g(n) in [0, 1] and error e(n) >= 0 [m] (for
/// example the mean deviation of the trial). Throws InvalidArgument for a gain outside [0, 1], a
/// negative or non-finite error, or a bad rule.
[[nodiscard]] double next_guidance_gain(double gain, double error_m, const FadingRule& rule = {});

}  // namespace calligraphy
