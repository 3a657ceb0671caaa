#include "calligraphy/render/guidance_mode.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

const char* to_string(GuidanceMode mode) noexcept {
  switch (mode) {
    case GuidanceMode::fixed:
      return "fixed";
    case GuidanceMode::fading:
      return "fading";
    case GuidanceMode::replay:
      return "replay";
  }
  return "?";
}

std::optional<GuidanceMode> guidance_mode_from_string(std::string_view name) noexcept {
  for (const GuidanceMode mode : {GuidanceMode::fixed, GuidanceMode::fading, GuidanceMode::replay}) {
    if (name == to_string(mode)) return mode;
  }
  return std::nullopt;
}

void validate_teacher_trajectory(std::span<const TeacherSample> samples) {
  if (samples.size() < 2) {
    throw InvalidArgument("teacher trajectory: " + std::to_string(samples.size()) +
                          " samples, at least 2 are needed");
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(samples[i].time_s) || !samples[i].position_m.allFinite()) {
      throw InvalidArgument("teacher trajectory: sample " + std::to_string(i) +
                            " has a time or position that is not finite");
    }
    if (i > 0 && samples[i].time_s < samples[i - 1].time_s) {
      throw InvalidArgument("teacher trajectory: sample " + std::to_string(i) + " at " +
                            std::to_string(samples[i].time_s) + " s comes before the previous sample at " +
                            std::to_string(samples[i - 1].time_s) + " s");
    }
  }
}

void FadingRule::validate() const {
  if (!(forgetting_factor >= 0.0 && forgetting_factor <= 1.0)) {
    throw InvalidArgument("FadingRule.forgetting_factor = " + std::to_string(forgetting_factor) +
                          " must be in [0, 1]");
  }
  if (!(error_gain_per_m >= 0.0) || !std::isfinite(error_gain_per_m)) {
    throw InvalidArgument("FadingRule.error_gain_per_m = " + std::to_string(error_gain_per_m) +
                          " must be finite and >= 0");
  }
}

double next_guidance_gain(double gain, double error_m, const FadingRule& rule) {
  rule.validate();
  if (!(gain >= 0.0 && gain <= 1.0)) {
    throw InvalidArgument("next_guidance_gain: gain = " + std::to_string(gain) + " must be in [0, 1]");
  }
  if (!(error_m >= 0.0) || !std::isfinite(error_m)) {
    throw InvalidArgument("next_guidance_gain: error_m = " + std::to_string(error_m) +
                          " must be finite and >= 0");
  }
  return std::clamp(rule.forgetting_factor * gain + rule.error_gain_per_m * error_m, 0.0, 1.0);
}

}  // namespace calligraphy
