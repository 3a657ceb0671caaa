#include "calligraphy/render/guidance_schedule.hpp"

#include <cmath>
#include <limits>
#include <variant>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

RepetitionGuidance GuidanceSchedule::start() const {
  RepetitionGuidance first;
  first.gain = start_gain;
  first.band_m = start_band_m;
  switch (adapts) {
    case AdaptiveGuidance::fading:
      first.mode = GuidanceMode::fading;
      break;
    case AdaptiveGuidance::assist_as_needed:
      first.mode = GuidanceMode::assist_as_needed;
      break;
    case AdaptiveGuidance::skill_adaptive:
      first.mode = GuidanceMode::fixed;  // the least skilled until the first repetition says otherwise
      break;
  }
  return first;
}

RepetitionGuidance GuidanceSchedule::next(const RepetitionGuidance& previous,
                                          std::optional<double> mean_deviation_m) const {
  RepetitionGuidance following = previous;
  switch (adapts) {
    case AdaptiveGuidance::fading:
      following.gain =
          mean_deviation_m ? next_guidance_gain(previous.gain, *mean_deviation_m, fading_rule) : 1.0;
      break;
    case AdaptiveGuidance::assist_as_needed:
      following.band_m = mean_deviation_m ? next_assist_band(previous.band_m, *mean_deviation_m, assist_rule)
                                          : assist_rule.min_band_m;
      break;
    case AdaptiveGuidance::skill_adaptive:
      // skill_adaptive_mode reads NaN as "no stroke written"; here that is nullopt, so a NaN given is
      // refused.
      if (mean_deviation_m && std::isnan(*mean_deviation_m)) {
        throw InvalidArgument(
            "GuidanceSchedule::next: mean_deviation_m = nan must be finite and >= 0 (no stroke written: "
            "none)");
      }
      following.mode = skill_adaptive_mode(
          mean_deviation_m ? *mean_deviation_m : std::numeric_limits<double>::quiet_NaN(), skill_rule);
      break;
  }
  return following;
}

GuidanceLaw GuidanceSchedule::law_of(const RepetitionGuidance& repetition, GuidanceLaw law) const {
  switch (adapts) {
    case AdaptiveGuidance::fading:
      if (auto* fading = std::get_if<FadingGuidance>(&law)) fading->gain = repetition.gain;
      break;
    case AdaptiveGuidance::assist_as_needed:
      if (auto* assist = std::get_if<AssistAsNeededGuidance>(&law)) assist->band_m = repetition.band_m;
      break;
    case AdaptiveGuidance::skill_adaptive:
      if (repetition.mode == GuidanceMode::error_amplification) return amplification;
      break;
  }
  return law;
}

}  // namespace calligraphy
