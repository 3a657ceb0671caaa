#pragma once
/// \file guidance_schedule.hpp
/// The one schedule of guidance that adapts over the repetitions of an item: the trainer, study sessions,
/// simulated cohorts and Python all take the next repetition's gain, band or mode from it, so that the same
/// outcomes give the same guidance wherever they are written (docs/force-rendering.md, "Guidance schedules").
#include <cstdint>
#include <optional>

#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/guidance_mode.hpp"

namespace calligraphy {

/// What adapts from one repetition to the next.
enum class AdaptiveGuidance : std::uint8_t {
  fading,            ///< the gain of eq. (8): `next_guidance_gain` (Emken, Benitez & Reinkensmeyer 2007)
  assist_as_needed,  ///< the band of the force tunnel: `next_assist_band` (Emken, Bobrow & Reinkensmeyer
                     ///< 2005)
  skill_adaptive,    ///< the mode, fixed fixture or error amplification: `skill_adaptive_mode` (Milot et al.
                     ///< 2010)
};

/// The guidance of one repetition of an item.
struct RepetitionGuidance {
  GuidanceMode mode = GuidanceMode::fixed;          ///< fading, assist-as-needed, or skill-adaptive's choice
  double gain = 1.0;                                ///< fading: the gain in [0, 1]
  double band_m = AssistAsNeededGuidance{}.band_m;  ///< assist-as-needed: the band [m] >= 0
  friend bool operator==(const RepetitionGuidance&, const RepetitionGuidance&) = default;
};

/// Start and rules of an adaptive guidance; `start()` is the first repetition's guidance, `next()` each
/// following one's from the previous repetition's guidance and outcome. A repetition that wrote no stroke
/// gives no error to adapt on: full guidance again (gain 1, the rule's narrowest band, the fixed fixture).
struct GuidanceSchedule {
  AdaptiveGuidance adapts = AdaptiveGuidance::fading;
  double start_gain = 1.0;                                ///< fading: the first repetition's gain in [0, 1]
  double start_band_m = AssistAsNeededGuidance{}.band_m;  ///< assist-as-needed: the first band [m] >= 0
  FadingRule fading_rule{};
  AssistBandRule assist_rule{};
  SkillAdaptiveRule skill_rule{};
  /// skill-adaptive: the error amplification it chooses for a writer within `skill_rule`'s threshold.
  ErrorAmplificationGuidance amplification{};

  /// The first repetition's guidance (skill-adaptive starts with the fixed fixture).
  [[nodiscard]] RepetitionGuidance start() const;
  /// The next repetition's guidance after `previous`, whose mean deviation from the strokes was
  /// `mean_deviation_m` [m] (nullopt: it wrote no stroke). Throws InvalidArgument as the rules' functions do
  /// (a gain outside [0, 1], a negative or non-finite deviation or band, a bad rule).
  [[nodiscard]] RepetitionGuidance next(const RepetitionGuidance& previous,
                                        std::optional<double> mean_deviation_m) const;
  /// The law a repetition with `repetition`'s guidance renders, from `law` (the one every repetition
  /// starts from): fading sets a FadingGuidance's gain, assist-as-needed an AssistAsNeededGuidance's band;
  /// skill-adaptive gives `amplification` when the repetition's mode is error amplification, else `law`.
  [[nodiscard]] GuidanceLaw law_of(const RepetitionGuidance& repetition, GuidanceLaw law) const;
};

}  // namespace calligraphy
