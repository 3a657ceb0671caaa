// A condition from its protocol "mode" and parameters, and the mode of a condition: the one place where the
// nine spellings meet the display, guidance law and schedule they stand for (protocol.hpp, StudyCondition).
#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/study/protocol.hpp"
#include "study/protocol_reading.hpp"

namespace calligraphy {
namespace study_detail {
namespace {

// Key `key` of the protocol as field `member` of a law's or rule's table, applied by `apply`.
template <typename S>
ModeParameter mode_parameter(std::string_view key, double S::*member,
                             void (*apply)(ConditionGuidance&, double)) {
  const ParameterField<S>& field = parameter_field(member);
  return {.key = key,
          .table = ParameterTable<S>::name,
          .field = field.name,
          .unit = field.unit,
          .doc = field.doc,
          .range = field.range,
          .bound = "",
          .apply = apply};
}

template <typename Law>
Law& law_of(ConditionGuidance& guidance) {
  return std::get<Law>(guidance.law);
}

// The schedule condition_from_mode made for the mode (guidance_schedule of it).
GuidanceSchedule& schedule_of(ConditionGuidance& guidance) { return guidance.schedule.value(); }

std::vector<ModeParameter> fading_parameters() {
  return {
      mode_parameter("start_gain", &FadingGuidance::gain,
                     [](ConditionGuidance& g, double v) {
                       law_of<FadingGuidance>(g).gain = v;
                       schedule_of(g).start_gain = v;
                     }),
      mode_parameter(
          "forgetting_factor", &FadingRule::forgetting_factor,
          [](ConditionGuidance& g, double v) { schedule_of(g).fading_rule.forgetting_factor = v; }),
      mode_parameter("error_gain_per_m", &FadingRule::error_gain_per_m, [](ConditionGuidance& g, double v) {
        schedule_of(g).fading_rule.error_gain_per_m = v;
      })};
}

std::vector<ModeParameter> replay_parameters() {
  ModeParameter lead =
      mode_parameter("max_lead_m", &ReplayGuidance::max_lead_m,
                     [](ConditionGuidance& g, double v) { law_of<ReplayGuidance>(g).max_lead_m = v; });
  // The table's range narrowed to the trial's R_res: the bound a trial checks.
  lead.range = protocol_max_lead_range();
  lead.bound = ", at most ForceLawParameters.constraint_radius_m";
  return {lead};
}

std::vector<ModeParameter> assist_parameters() {
  return {
      mode_parameter("start_band_m", &AssistAsNeededGuidance::band_m,
                     [](ConditionGuidance& g, double v) {
                       law_of<AssistAsNeededGuidance>(g).band_m = v;
                       schedule_of(g).start_band_m = v;
                     }),
      mode_parameter("target_error_m", &AssistBandRule::target_error_m,
                     [](ConditionGuidance& g, double v) { schedule_of(g).assist_rule.target_error_m = v; }),
      mode_parameter("band_rate", &AssistBandRule::rate,
                     [](ConditionGuidance& g, double v) { schedule_of(g).assist_rule.rate = v; }),
      mode_parameter("min_band_m", &AssistBandRule::min_band_m,
                     [](ConditionGuidance& g, double v) { schedule_of(g).assist_rule.min_band_m = v; }),
      mode_parameter("max_band_m", &AssistBandRule::max_band_m,
                     [](ConditionGuidance& g, double v) { schedule_of(g).assist_rule.max_band_m = v; })};
}

std::vector<ModeParameter> amplification_parameters() {
  return {
      mode_parameter("amplification_gain", &ErrorAmplificationGuidance::gain,
                     [](ConditionGuidance& g, double v) { law_of<ErrorAmplificationGuidance>(g).gain = v; }),
      mode_parameter(
          "max_force_n", &ErrorAmplificationGuidance::max_force_n,
          [](ConditionGuidance& g, double v) { law_of<ErrorAmplificationGuidance>(g).max_force_n = v; })};
}

// Skill-adaptive's error amplification is its schedule's (the law is the fixed fixture it starts with).
std::vector<ModeParameter> skill_parameters() {
  return {
      mode_parameter("threshold_m", &SkillAdaptiveRule::threshold_m,
                     [](ConditionGuidance& g, double v) { schedule_of(g).skill_rule.threshold_m = v; }),
      mode_parameter("amplification_gain", &ErrorAmplificationGuidance::gain,
                     [](ConditionGuidance& g, double v) { schedule_of(g).amplification.gain = v; }),
      mode_parameter("max_force_n", &ErrorAmplificationGuidance::max_force_n,
                     [](ConditionGuidance& g, double v) { schedule_of(g).amplification.max_force_n = v; })};
}

std::vector<ModeParameter> timing_parameters() {
  return {mode_parameter("speed_m_s", &TimingGuidance::speed_m_s,
                         [](ConditionGuidance& g, double v) { law_of<TimingGuidance>(g).speed_m_s = v; })};
}

GuidanceSchedule adapting(AdaptiveGuidance adapts) {
  GuidanceSchedule schedule;
  schedule.adapts = adapts;
  return schedule;
}

// The guidance of `mode` with its parameters' defaults; empty for the modes without guidance.
std::optional<ConditionGuidance> default_guidance(ConditionMode mode) {
  ConditionGuidance guidance;
  switch (mode) {
    case ConditionMode::vision:
    case ConditionMode::quiz:
      return std::nullopt;
    case ConditionMode::haptic:
      guidance.law = FixedGuidance{};
      break;
    case ConditionMode::fading:
      guidance.schedule = adapting(AdaptiveGuidance::fading);
      guidance.law = FadingGuidance{.gain = guidance.schedule->start_gain};
      break;
    case ConditionMode::replay:
      guidance.law = ReplayGuidance{};
      break;
    case ConditionMode::assist_as_needed:
      guidance.schedule = adapting(AdaptiveGuidance::assist_as_needed);
      guidance.law = AssistAsNeededGuidance{.band_m = guidance.schedule->start_band_m};
      break;
    case ConditionMode::error_amplification:
      guidance.law = ErrorAmplificationGuidance{};
      break;
    case ConditionMode::skill_adaptive:
      guidance.schedule = adapting(AdaptiveGuidance::skill_adaptive);
      guidance.law = FixedGuidance{};  // the first repetition's; the schedule chooses each later one's
      break;
    case ConditionMode::timing:
      guidance.law = TimingGuidance{};
      break;
  }
  return guidance;
}

}  // namespace

std::span<const ModeParameter> mode_parameters(ConditionMode mode) {
  static const std::vector<ModeParameter> none;
  static const std::vector<ModeParameter> fading = fading_parameters();
  static const std::vector<ModeParameter> replay = replay_parameters();
  static const std::vector<ModeParameter> assist = assist_parameters();
  static const std::vector<ModeParameter> amplification = amplification_parameters();
  static const std::vector<ModeParameter> skill = skill_parameters();
  static const std::vector<ModeParameter> timing = timing_parameters();
  switch (mode) {
    case ConditionMode::fading:
      return fading;
    case ConditionMode::replay:
      return replay;
    case ConditionMode::assist_as_needed:
      return assist;
    case ConditionMode::error_amplification:
      return amplification;
    case ConditionMode::skill_adaptive:
      return skill;
    case ConditionMode::timing:
      return timing;
    case ConditionMode::vision:
    case ConditionMode::haptic:
    case ConditionMode::quiz:
      break;
  }
  return none;
}

std::string parameter_range_message(const ModeParameter& parameter, double value) {
  std::string message = "expected a number ";
  message.append(parameter.range.text(parameter.unit))
      .append(" (")
      .append(parameter.table)
      .append(".")
      .append(parameter.field)
      .append(parameter.bound)
      .append("), got ")
      .append(nlohmann::json(value).dump());
  return message;
}

}  // namespace study_detail

StudyCondition condition_from_mode(ConditionMode mode, const std::map<std::string, double>& parameters) {
  StudyCondition condition;
  if (mode == ConditionMode::quiz) condition.quiz = QuizOptions{};
  condition.guidance = study_detail::default_guidance(mode);
  const std::span<const study_detail::ModeParameter> taken = study_detail::mode_parameters(mode);
  for (const auto& given : parameters) {
    const std::string& key = given.first;
    const double value = given.second;
    const auto parameter = std::find_if(taken.begin(), taken.end(),
                                        [&](const study_detail::ModeParameter& p) { return p.key == key; });
    if (parameter == taken.end()) {
      std::string message = "mode \"";
      message.append(to_string(mode)).append("\" takes no parameter \"").append(key).append("\"");
      throw InvalidArgument(message);
    }
    if (!parameter->range.contains(value)) {
      std::string message = "parameter \"";
      message.append(key).append("\": ").append(study_detail::parameter_range_message(*parameter, value));
      throw InvalidArgument(message);
    }
    parameter->apply(*condition.guidance, value);
  }
  condition.guidance_parameters = parameters;
  return condition;
}

ConditionMode condition_mode(const StudyCondition& condition) noexcept {
  if (condition.quiz) return ConditionMode::quiz;
  if (!condition.guidance) return ConditionMode::vision;
  if (const std::optional<GuidanceSchedule>& schedule = condition.guidance->schedule) {
    switch (schedule->adapts) {
      case AdaptiveGuidance::fading:
        return ConditionMode::fading;
      case AdaptiveGuidance::assist_as_needed:
        return ConditionMode::assist_as_needed;
      case AdaptiveGuidance::skill_adaptive:
        return ConditionMode::skill_adaptive;
    }
  }
  switch (mode_of(condition.guidance->law)) {
    case GuidanceMode::fixed:
      return ConditionMode::haptic;
    case GuidanceMode::fading:
      return ConditionMode::fading;
    case GuidanceMode::replay:
      return ConditionMode::replay;
    case GuidanceMode::assist_as_needed:
      return ConditionMode::assist_as_needed;
    case GuidanceMode::error_amplification:
      return ConditionMode::error_amplification;
    case GuidanceMode::timing:
      return ConditionMode::timing;
  }
  return ConditionMode::haptic;
}

}  // namespace calligraphy
