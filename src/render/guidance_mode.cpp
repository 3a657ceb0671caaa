#include "calligraphy/render/guidance_mode.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

namespace {

constexpr ParameterRange kShortLength{.low = 0.0, .high = 0.1};
constexpr ParameterRange kPositiveShortLength{.low = 0.0, .high = 0.1, .low_open = true};

constexpr std::array kFadingRuleFields{
    ParameterField<FadingRule>{"forgetting_factor", "", ParameterRange{.low = 0.0, .high = 1.0},
                               "f, the share of this repetition's gain the next one keeps",
                               &FadingRule::forgetting_factor},
    ParameterField<FadingRule>{"error_gain_per_m", "1/m", ParameterRange{.low = 0.0, .high = 1e6},
                               "k, the gain added per metre of mean deviation",
                               &FadingRule::error_gain_per_m},
};
constexpr std::array kAssistRuleFields{
    ParameterField<AssistBandRule>{"target_error_m", "m", kPositiveShortLength,
                                   "e*, the deviation the band adapts towards",
                                   &AssistBandRule::target_error_m},
    ParameterField<AssistBandRule>{"rate", "", ParameterRange{.low = 0.0, .high = 100.0},
                                   "k, the band's change per metre of error below the target",
                                   &AssistBandRule::rate},
    ParameterField<AssistBandRule>{"min_band_m", "m", kShortLength, "b_min, the narrowest band",
                                   &AssistBandRule::min_band_m},
    ParameterField<AssistBandRule>{"max_band_m", "m", kShortLength, "b_max, the widest band, at least b_min",
                                   &AssistBandRule::max_band_m},
};
constexpr std::array kSkillRuleFields{
    ParameterField<SkillAdaptiveRule>{"threshold_m", "m", kPositiveShortLength,
                                      "the error at or above which the writer is guided",
                                      &SkillAdaptiveRule::threshold_m},
};

}  // namespace

std::span<const ParameterField<FadingRule>> ParameterTable<FadingRule>::fields() noexcept {
  return kFadingRuleFields;
}
std::span<const ParameterField<AssistBandRule>> ParameterTable<AssistBandRule>::fields() noexcept {
  return kAssistRuleFields;
}
std::span<const ParameterField<SkillAdaptiveRule>> ParameterTable<SkillAdaptiveRule>::fields() noexcept {
  return kSkillRuleFields;
}

const char* to_string(GuidanceMode mode) noexcept { return enum_spelling(mode).data(); }

std::span<const GuidanceMode> guidance_modes() noexcept {
  static constexpr auto kModes = [] {
    std::array<GuidanceMode, EnumTable<GuidanceMode>::entries.size()> out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = EnumTable<GuidanceMode>::entries[i].value;
    return out;
  }();
  return kModes;
}

const char* guidance_mode_names() noexcept {
  static const std::string names = join_spellings(enum_spellings<GuidanceMode>(), "|");
  return names.c_str();
}

std::optional<GuidanceMode> guidance_mode_from_string(std::string_view name) noexcept {
  return enum_from_spelling<GuidanceMode>(name);
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
                            shortest_decimal(samples[i].time_s) + " s comes before the previous sample at " +
                            shortest_decimal(samples[i - 1].time_s) + " s");
    }
  }
}

void FadingRule::validate() const { check_parameters(*this); }

double next_guidance_gain(double gain, double error_m, const FadingRule& rule) {
  rule.validate();
  if (!(gain >= 0.0 && gain <= 1.0)) {
    throw InvalidArgument("next_guidance_gain: gain = " + shortest_decimal(gain) + " must be in [0, 1]");
  }
  if (!(error_m >= 0.0) || !std::isfinite(error_m)) {
    throw InvalidArgument("next_guidance_gain: error_m = " + shortest_decimal(error_m) +
                          " must be finite and >= 0");
  }
  return std::clamp(rule.forgetting_factor * gain + rule.error_gain_per_m * error_m, 0.0, 1.0);
}

namespace {

void check_length(double value, const char* name, bool positive) {
  if (!std::isfinite(value) || value < 0.0 || (positive && value == 0.0)) {
    throw InvalidArgument(std::string(name) + " = " + shortest_decimal(value) +
                          (positive ? " must be finite and > 0" : " must be finite and >= 0"));
  }
}

}  // namespace

void AssistBandRule::validate() const {
  check_parameters(*this);
  if (max_band_m < min_band_m) {
    throw InvalidArgument("AssistBandRule.max_band_m = " + shortest_decimal(max_band_m) +
                          " must be >= min_band_m = " + shortest_decimal(min_band_m));
  }
}

double next_assist_band(double band_m, double error_m, const AssistBandRule& rule) {
  rule.validate();
  check_length(band_m, "next_assist_band: band_m", false);
  check_length(error_m, "next_assist_band: error_m", false);
  return std::clamp(band_m + rule.rate * (rule.target_error_m - error_m), rule.min_band_m, rule.max_band_m);
}

void SkillAdaptiveRule::validate() const { check_parameters(*this); }

GuidanceMode skill_adaptive_mode(double previous_error_m, const SkillAdaptiveRule& rule) {
  rule.validate();
  if (std::isnan(previous_error_m)) return GuidanceMode::fixed;
  check_length(previous_error_m, "skill_adaptive_mode: previous_error_m", false);
  return previous_error_m >= rule.threshold_m ? GuidanceMode::fixed : GuidanceMode::error_amplification;
}

}  // namespace calligraphy
