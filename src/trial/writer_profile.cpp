#include "calligraphy/trial/writer_profile.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"

namespace calligraphy {
namespace {

using Field = ParameterField<WriterProfile>;
using W = WriterProfile;
constexpr double kInf = std::numeric_limits<double>::infinity();
// [low, high]; open ends where a value of the bound itself would be meaningless (no stiffness, no speed).
constexpr ParameterRange closed(double low, double high) { return {.low = low, .high = high}; }
constexpr ParameterRange above(double low, double high) {
  return {.low = low, .high = high, .low_open = true};
}
constexpr ParameterRange kProbability = closed(0.0, 1.0);

// Every numeric field but `max_attempts_per_stroke` (an int, handled on its own), in declaration order: the
// one definition of each range (docs/writer.md has the sources of the defaults).
constexpr std::array kFields{
    Field{"hand_stiffness_n_per_m", "N/m", above(0.0, 1e4), "k, the hand's stiffness holding the stylus",
          &W::hand_stiffness_n_per_m},
    Field{"hand_damping_n_s_per_m", "N s/m", closed(0.0, 1e3), "b, the hand's damping",
          &W::hand_damping_n_s_per_m},
    Field{"noise_fraction", "", closed(0.0, 1.0),
          "signal-dependent force noise, std dev over |F| (Harris & Wolpert 1998)", &W::noise_fraction},
    Field{"tremor_amplitude_n", "N", closed(0.0, 10.0), "in-plane tremor force amplitude",
          &W::tremor_amplitude_n},
    Field{"tremor_frequency_hz", "Hz", above(0.0, 100.0), "tremor frequency (8-12 Hz physiological)",
          &W::tremor_frequency_hz},
    Field{"writing_speed_m_s", "m/s", above(0.0, 10.0), "mean writing speed with the pen on the stroke",
          &W::writing_speed_m_s},
    Field{"travel_speed_m_s", "m/s", above(0.0, 10.0), "mean speed of pen-up moves", &W::travel_speed_m_s},
    Field{"press_depth_m", "m", closed(0.0, 0.1), "how far below the paper the hand aims while writing",
          &W::press_depth_m},
    Field{"lift_height_m", "m", above(0.0, 0.2), "pen-up height above the paper", &W::lift_height_m},
    Field{"corner_cut_m", "m", closed(0.0, 0.02), "most the writer cuts inside a corner (uniform per corner)",
          &W::corner_cut_m},
    Field{"end_short_m", "m", closed(0.0, 0.02),
          "the pen lifts uniformly between this short of the seen end and end_past_m past it",
          &W::end_short_m},
    Field{"end_past_m", "m", closed(0.0, 0.02), "see end_short_m", &W::end_past_m},
    Field{"follow_through_m", "m", closed(0.0, 0.05),
          "a run past the end added to the end draw (a brush's exit)", &W::follow_through_m},
    Field{"bias_offset_m", "m", closed(0.0, 0.05), "offset of the writer's whole copy", &W::bias_offset_m},
    Field{"scale_error",
          "",
          {.low = -0.5, .high = 0.5, .low_open = true, .high_open = true},
          "relative mis-scale of the copy about the character centre",
          &W::scale_error},
    Field{"stroke_jitter_m", "m", closed(0.0, 0.05), "std dev of a per-attempt random offset",
          &W::stroke_jitter_m},
    Field{"visual_delay_s", "s", closed(0.0, 0.5),
          "visuomotor delay (Miall et al. 1993; Saunders & Knill 2005)", &W::visual_delay_s},
    Field{"vision_period_s", "s", closed(0.001, 0.1), "interval between visual updates", &W::vision_period_s},
    Field{"correction_rate_per_s", "1/s", closed(0.0, 100.0),
          "rate at which a seen error beyond the tolerance is removed", &W::correction_rate_per_s},
    Field{"error_tolerance_m", "m", closed(0.0, 0.05), "seen error the writer leaves uncorrected",
          &W::error_tolerance_m},
    Field{"steering_width_m", "m", above(0.0, 0.1),
          "width W of the tunnel in the steering law v = (W - 2|e|) / tau", &W::steering_width_m},
    Field{"min_speed_fraction",
          "",
          {.low = 0.0, .high = 1.0, .low_open = true},
          "least share of writing_speed_m_s however large the error",
          &W::min_speed_fraction},
    Field{"error_filter_s", "s", above(0.0, 10.0), "time constant of the seen error that sets the speed",
          &W::error_filter_s},
    Field{"speed_time_constant_s", "s", above(0.0, 10.0), "time constant of the speed command",
          &W::speed_time_constant_s},
    Field{"reaction_time_s", "s", above(0.0, 10.0), "how long a resistance lasts before the writer reacts",
          &W::reaction_time_s},
    Field{"resistance_threshold_n", "N", above(0.0, 100.0),
          "in-plane force against the intended motion that counts as resistance", &W::resistance_threshold_n},
    Field{"expected_drag_ratio", "", closed(0.0, 10.0),
          "paper drag the writer takes as normal, share of the normal force", &W::expected_drag_ratio},
    Field{"correction_per_attempt", "", closed(0.0, 1.0),
          "share of the bias and error rates removed on each re-attempt", &W::correction_per_attempt},
    Field{"order_error_probability", "", kProbability,
          "a stroke is swapped with the next one in the writer's order", &W::order_error_probability},
    Field{"backwards_probability", "", kProbability, "a stroke is written from its end to its start",
          &W::backwards_probability},
    Field{"mid_stroke_lift_probability", "", kProbability, "the pen is lifted in the middle of a stroke",
          &W::mid_stroke_lift_probability},
    Field{"outside_touch_probability", "", kProbability,
          "the pen touches the paper outside the character's box (AS)", &W::outside_touch_probability},
    Field{"hesitation_probability", "", kProbability, "the writer pauses before a stroke or at a corner",
          &W::hesitation_probability},
    Field{"hesitation_s", "s", closed(0.0, 60.0), "mean length of a pause", &W::hesitation_s},
    Field{"learning_rate", "", closed(0.0, kInf),
          "lambda of the exponential practice law per repetition; 0 = no learning", &W::learning_rate},
};
constexpr const char* kAttemptsKey = "max_attempts_per_stroke";

std::string known_keys() {
  std::string list;
  for (const std::string& name : writer_parameter_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

const Field* find_field(std::string_view key) {
  for (const Field& f : kFields) {
    if (key == f.name) return &f;
  }
  return nullptr;
}

[[noreturn]] void unknown_key(std::string_view key) {
  throw InvalidArgument("unknown writer parameter '" + std::string(key) + "'; known: " + known_keys());
}

}  // namespace

std::span<const ParameterField<WriterProfile>> ParameterTable<WriterProfile>::fields() noexcept {
  return kFields;
}

WriterProfile WriterProfile::novice() { return WriterProfile{}; }

WriterProfile WriterProfile::skilled() {
  WriterProfile p;
  p.name = "skilled";
  p.hand_stiffness_n_per_m = 600.0;
  p.hand_damping_n_s_per_m = 8.0;
  p.writing_speed_m_s = 0.04;
  p.bias_offset_m = 0.0005;
  p.scale_error = 0.02;
  p.stroke_jitter_m = 0.0003;
  p.noise_fraction = 0.02;
  p.tremor_amplitude_n = 0.01;
  p.error_tolerance_m = 0.0005;
  p.mid_stroke_lift_probability = 0.0;
  p.outside_touch_probability = 0.0;
  p.hesitation_probability = 0.0;
  return p;
}

WriterProfile WriterProfile::foreign() {
  WriterProfile p;
  p.name = "foreign";
  p.writing_speed_m_s = 0.018;
  p.bias_offset_m = 0.003;
  p.scale_error = 0.1;
  p.stroke_jitter_m = 0.0015;
  p.error_tolerance_m = 0.0015;
  p.order_error_probability = 0.25;
  p.backwards_probability = 0.12;
  p.mid_stroke_lift_probability = 0.05;
  p.outside_touch_probability = 0.05;
  p.hesitation_probability = 0.2;
  p.hesitation_s = 0.8;
  return p;
}

void WriterProfile::validate() const {
  check_parameters(*this);
  if (max_attempts_per_stroke < 1 || max_attempts_per_stroke > 1000) {
    throw InvalidArgument("WriterProfile.max_attempts_per_stroke = " +
                          std::to_string(max_attempts_per_stroke) + " must be in [1, 1000]");
  }
}

namespace {
struct NamedProfile {
  std::string_view name;
  WriterProfile (*make)();
};
constexpr std::array<NamedProfile, 3> kNamedProfiles{{
    {"novice", &WriterProfile::novice},
    {"skilled", &WriterProfile::skilled},
    {"foreign", &WriterProfile::foreign},
}};
constexpr std::array<std::string_view, kNamedProfiles.size()> kProfileNames{
    kNamedProfiles[0].name, kNamedProfiles[1].name, kNamedProfiles[2].name};
}  // namespace

std::span<const std::string_view> writer_profile_names() noexcept { return kProfileNames; }

WriterProfile writer_profile(std::string_view name) {
  for (const NamedProfile& profile : kNamedProfiles) {
    if (profile.name == name) return profile.make();
  }
  throw InvalidArgument("unknown writer profile '" + std::string(name) +
                        "'; known: " + join_spellings(kProfileNames, ", "));
}

std::vector<std::string> writer_parameter_names() {
  std::vector<std::string> names;
  for (const Field& f : kFields) names.emplace_back(f.name);
  names.emplace_back(kAttemptsKey);
  return names;
}

double writer_parameter(const WriterProfile& profile, std::string_view key) {
  if (key == kAttemptsKey) return static_cast<double>(profile.max_attempts_per_stroke);
  const Field* f = find_field(key);
  if (f == nullptr) unknown_key(key);
  return profile.*(f->member);
}

void set_writer_parameter(WriterProfile& profile, std::string_view key, double value) {
  WriterProfile changed = profile;
  if (key == kAttemptsKey) {
    if (!std::isfinite(value) || value != std::floor(value) || std::abs(value) > 1e9) {
      throw InvalidArgument("writer parameter max_attempts_per_stroke = " + shortest_decimal(value) +
                            " must be a whole number");
    }
    changed.max_attempts_per_stroke = static_cast<int>(value);
  } else {
    const Field* f = find_field(key);
    if (f == nullptr) unknown_key(key);
    changed.*(f->member) = value;
  }
  changed.validate();
  profile = std::move(changed);
}

}  // namespace calligraphy
