#include "calligraphy/sim/writer_memory.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// The error the writer experiences: what it has still to learn, less the share the guidance corrects.
double error_of(const SkillMemory& memory, double assistance_share) {
  return (1.0 - memory.skill()) * (1.0 - assistance_share);
}

void learn(SkillMemory& memory, double error, const TwoStateRates& rates) {
  memory.fast += rates.fast_learning * error;
  memory.slow += rates.slow_learning * error;
}

void decay(SkillMemory& memory, const TwoStateRates& rates) {
  memory.fast *= rates.fast_retention;
  memory.slow *= rates.slow_retention;
}

// The mean skill of `keys` (one per stroke or character, repeats counted); 0 for one never practised.
template <typename Key, typename Keys>
double mean_skill(const std::map<Key, SkillMemory>& skills, const Keys& keys) {
  if (keys.empty()) return 0.0;
  double sum = 0.0;
  for (const Key key : keys) {
    const auto found = skills.find(key);
    sum += found == skills.end() ? 0.0 : found->second.skill();
  }
  return sum / static_cast<double>(keys.size());
}

double blend(double own, double skilled, double skill) { return own + (skilled - own) * skill; }

void check_skill(double skill, const char* name) {
  if (!(skill >= 0.0 && skill <= 1.0)) {
    throw InvalidArgument(std::string("learned_profile: ") + name + " skill " + shortest_decimal(skill) +
                          " outside [0, 1]");
  }
}

}  // namespace

namespace {

// Smith, Ghazizadeh & Shadmehr (2006): a retention factor is a share kept per trial, a learning rate a share
// of the error learned per trial.
constexpr std::array kTwoStateFields{
    ParameterField<TwoStateRates>{
        "fast_retention", "", ParameterRange{.low = 0.0, .high = 1.0, .high_open = true},
        "A_f, share of the fast state kept per trial", &TwoStateRates::fast_retention},
    ParameterField<TwoStateRates>{
        "fast_learning", "", ParameterRange{.low = 0.0, .high = 1.0, .low_open = true},
        "B_f, share of the error the fast state learns per trial", &TwoStateRates::fast_learning},
    ParameterField<TwoStateRates>{
        "slow_retention", "", ParameterRange{.low = 0.0, .high = 1.0, .high_open = true},
        "A_s, share of the slow state kept per trial (above A_f)", &TwoStateRates::slow_retention},
    ParameterField<TwoStateRates>{
        "slow_learning", "", ParameterRange{.low = 0.0, .high = 1.0, .low_open = true},
        "B_s, share of the error the slow state learns per trial (below B_f)", &TwoStateRates::slow_learning},
};

}  // namespace

std::span<const ParameterField<TwoStateRates>> ParameterTable<TwoStateRates>::fields() noexcept {
  return kTwoStateFields;
}

const Schema& SchemaOf<TwoStateRates>::get() {
  return table_schema<TwoStateRates>(
      "the two-state model's retention factors and learning rates per trial (Smith, Ghazizadeh & Shadmehr "
      "2006)",
      validate_of<TwoStateRates>);
}

void TwoStateRates::validate() const {
  check_parameters(*this);
  // The rules between fields: the slow state retains more and learns less than the fast one.
  if (!(slow_retention > fast_retention)) {
    throw InvalidArgument("TwoStateRates.slow_retention = " + shortest_decimal(slow_retention) +
                          " must be in (fast_retention, 1)");
  }
  if (!(slow_learning < fast_learning)) {
    throw InvalidArgument("TwoStateRates.slow_learning = " + shortest_decimal(slow_learning) +
                          " must be in (0, fast_learning)");
  }
}

double SkillMemory::skill() const noexcept { return std::clamp(fast + slow, 0.0, 1.0); }

double guidance_assistance_share(double gain, double guidance_stiffness_n_per_m,
                                 double hand_stiffness_n_per_m) {
  if (!(gain >= 0.0 && gain <= 1.0)) {
    throw InvalidArgument("guidance gain " + shortest_decimal(gain) + " outside [0, 1]");
  }
  if (!(guidance_stiffness_n_per_m >= 0.0) || !std::isfinite(guidance_stiffness_n_per_m)) {
    throw InvalidArgument("guidance stiffness " + shortest_decimal(guidance_stiffness_n_per_m) +
                          " N/m must be finite and >= 0");
  }
  if (!(hand_stiffness_n_per_m > 0.0) || !std::isfinite(hand_stiffness_n_per_m)) {
    throw InvalidArgument("hand stiffness " + shortest_decimal(hand_stiffness_n_per_m) +
                          " N/m must be finite and > 0");
  }
  const double guide = gain * guidance_stiffness_n_per_m;
  return guide / (guide + hand_stiffness_n_per_m);
}

void practise(WriterMemory& memory, const std::vector<int>& typical_ids, const std::u32string& characters,
              const AssistanceShares& shares, const TwoStateRates& rates) {
  rates.validate();
  for (const auto& [name, share] : {std::pair{"shape", shares.shape}, std::pair{"timing", shares.timing}}) {
    if (!(share >= kMinAssistanceShare && share <= 1.0)) {
      throw InvalidArgument(std::string("practise: ") + name + " assistance share " +
                            shortest_decimal(share) + " outside [" + shortest_decimal(kMinAssistanceShare) +
                            ", 1]");
    }
  }
  // x(n+1) = A x(n) + B e(n), e(n) from the skill before the trial; a stroke type written k times learns k
  // times from that error.
  if (!(shares.timing_demonstration >= 0.0 && shares.timing_demonstration <= 1.0)) {
    throw InvalidArgument("practise: timing demonstration " + shortest_decimal(shares.timing_demonstration) +
                          " outside [0, 1]");
  }
  std::map<int, double> shape_errors;
  std::map<int, double> timing_errors;
  for (const int id : typical_ids) {
    shape_errors[id] += error_of(memory.typical_strokes[id], shares.shape);
    // Timing: the share of its own error the writer perceives, plus what a guide demonstrated.
    const SkillMemory& timing = memory.stroke_timing[id];
    timing_errors[id] += kSeenTimingShare * error_of(timing, shares.timing) +
                         (1.0 - timing.skill()) * shares.timing_demonstration;
  }
  std::map<char32_t, double> character_errors;
  for (const char32_t c : characters) character_errors[c] += error_of(memory.characters[c], shares.shape);
  for (auto& [id, skill] : memory.typical_strokes) decay(skill, rates);
  for (auto& [id, skill] : memory.stroke_timing) decay(skill, rates);
  for (auto& [character, skill] : memory.characters) decay(skill, rates);
  for (const auto& [id, error] : shape_errors) learn(memory.typical_strokes[id], error, rates);
  for (const auto& [id, error] : timing_errors) learn(memory.stroke_timing[id], error, rates);
  for (const auto& [c, error] : character_errors) learn(memory.characters[c], error, rates);
}

void consolidate(WriterMemory& memory) {
  for (auto& [id, skill] : memory.typical_strokes) skill.fast = 0.0;
  for (auto& [id, skill] : memory.stroke_timing) skill.fast = 0.0;
  for (auto& [character, skill] : memory.characters) skill.fast = 0.0;
}

double shape_skill(const WriterMemory& memory, const std::vector<int>& typical_ids) {
  return mean_skill(memory.typical_strokes, typical_ids);
}

double timing_skill(const WriterMemory& memory, const std::vector<int>& typical_ids) {
  return mean_skill(memory.stroke_timing, typical_ids);
}

double order_skill(const WriterMemory& memory, const std::u32string& characters) {
  return mean_skill(memory.characters, characters);
}

WriterSkills writer_skills(const WriterMemory& memory, const std::vector<int>& typical_ids,
                           const std::u32string& characters) {
  return {shape_skill(memory, typical_ids), order_skill(memory, characters),
          timing_skill(memory, typical_ids)};
}

const std::vector<std::string>& learned_profile_fields() {
  static const std::vector<std::string> fields{"bias_offset_m",
                                               "scale_error",
                                               "stroke_jitter_m",
                                               "corner_cut_m",
                                               "writing_speed_m_s",
                                               "mid_stroke_lift_probability",
                                               "outside_touch_probability",
                                               "hesitation_probability",
                                               "order_error_probability",
                                               "backwards_probability"};
  return fields;
}

WriterProfile learned_profile(const WriterProfile& own, const WriterProfile& skilled,
                              const WriterSkills& skills) {
  check_skill(skills.shape, "shape");
  check_skill(skills.order, "order");
  check_skill(skills.timing, "timing");
  const double shape = skills.shape;
  WriterProfile p = own;
  p.bias_offset_m = blend(own.bias_offset_m, skilled.bias_offset_m, shape);
  p.scale_error = blend(own.scale_error, skilled.scale_error, shape);
  p.stroke_jitter_m = blend(own.stroke_jitter_m, skilled.stroke_jitter_m, shape);
  p.corner_cut_m = blend(own.corner_cut_m, skilled.corner_cut_m, shape);
  p.mid_stroke_lift_probability =
      blend(own.mid_stroke_lift_probability, skilled.mid_stroke_lift_probability, shape);
  p.outside_touch_probability =
      blend(own.outside_touch_probability, skilled.outside_touch_probability, shape);
  p.writing_speed_m_s = blend(own.writing_speed_m_s, skilled.writing_speed_m_s, skills.timing);
  p.hesitation_probability = blend(own.hesitation_probability, skilled.hesitation_probability, skills.timing);
  p.order_error_probability =
      blend(own.order_error_probability, skilled.order_error_probability, skills.order);
  p.backwards_probability = blend(own.backwards_probability, skilled.backwards_probability, skills.order);
  p.validate();
  return p;
}

}  // namespace calligraphy
