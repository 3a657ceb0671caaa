#include "calligraphy/sim/subject_traits.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// A stream of the subject's own, apart from the trials' seeds (which mix the same seed with the trial's
// position): the seed xor'ed with a fixed tag ("traits" in ASCII).
constexpr std::uint64_t kTraitsStream = 0x0000747261697473ULL;

// One standard normal draw by Box-Muller from two 53-bit uniforms (std::normal_distribution is not the same
// on every standard library, and a subject must be the same person on every computer).
double standard_normal(std::mt19937_64& rng) {
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1p-53; };
  const double u1 = 1.0 - uniform();  // in (0, 1]: the log is finite
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// A retention factor A whose time constant 1 / (1 - A) [trials] is multiplied by `factor`.
double retention_scaled(double retention, double factor) { return 1.0 - (1.0 - retention) / factor; }

void check_factor(double value, const char* name) {
  if (!std::isfinite(value) || !(value > 0.0)) {
    throw InvalidArgument(std::string("SubjectTraits.") + name + " = " + shortest_decimal(value) +
                          " must be finite and > 0");
  }
}

}  // namespace

namespace {

// A log-SD of 2 spreads a trait's middle 95 % over a factor of about 2,500 (e^(2 x 1.96 x 2)): far past the
// spreads docs/writer.md ("Individual differences") takes, 0.2 to 0.5.
constexpr ParameterRange kLogSd{.low = 0.0, .high = 2.0};
constexpr std::array kSpreadFields{
    ParameterField<SubjectSpread>{"writing_speed", "", kLogSd, "log-SD of the writing speed factor",
                                  &SubjectSpread::writing_speed},
    ParameterField<SubjectSpread>{"spatial_error", "", kLogSd,
                                  "log-SD of bias, scale error, jitter, corner cut and error tolerance",
                                  &SubjectSpread::spatial_error},
    ParameterField<SubjectSpread>{"error_rate", "", kLogSd, "log-SD of the error probabilities",
                                  &SubjectSpread::error_rate},
    ParameterField<SubjectSpread>{"motor_noise", "", kLogSd,
                                  "log-SD of the force noise fraction and the tremor amplitude",
                                  &SubjectSpread::motor_noise},
    ParameterField<SubjectSpread>{"learning_rate", "", kLogSd,
                                  "log-SD of the two-state learning rates B_f and B_s (one factor)",
                                  &SubjectSpread::learning_rate},
    ParameterField<SubjectSpread>{"retention_time", "", kLogSd,
                                  "log-SD of the retention time constants 1 / (1 - A) (one factor)",
                                  &SubjectSpread::retention_time},
};

}  // namespace

std::span<const ParameterField<SubjectSpread>> ParameterTable<SubjectSpread>::fields() noexcept {
  return kSpreadFields;
}

const Schema& SchemaOf<SubjectSpread>::get() {
  return table_schema<SubjectSpread>("log-normal spreads of a simulated subject's traits about its profile");
}

void SubjectSpread::validate() const { check_parameters(*this); }

SubjectTraits draw_subject_traits(std::uint64_t subject_seed, const SubjectSpread& spread) {
  spread.validate();
  std::mt19937_64 rng(subject_seed ^ kTraitsStream);
  // Draws in a fixed order; each factor is exp(sigma z), median 1.
  const auto factor = [&rng](double sigma) { return std::exp(sigma * standard_normal(rng)); };
  SubjectTraits traits;
  traits.drawn = true;
  traits.writing_speed_factor = factor(spread.writing_speed);
  traits.spatial_error_factor = factor(spread.spatial_error);
  traits.error_rate_factor = factor(spread.error_rate);
  traits.motor_noise_factor = factor(spread.motor_noise);
  const double learning = factor(spread.learning_rate);
  const double retention = factor(spread.retention_time);
  const TwoStateRates typical{};
  // One factor on both rates and one on both time constants keeps B_s < B_f and A_s > A_f.
  traits.learning.fast_learning = std::min(typical.fast_learning * learning, 1.0);
  traits.learning.slow_learning =
      std::min(typical.slow_learning * learning, 0.5 * traits.learning.fast_learning);
  traits.learning.fast_retention = std::max(retention_scaled(typical.fast_retention, retention), 0.0);
  traits.learning.slow_retention = retention_scaled(typical.slow_retention, retention);
  traits.learning.validate();
  return traits;
}

const std::vector<std::string>& individual_profile_fields() {
  static const std::vector<std::string> fields{
      "writing_speed_m_s",         "bias_offset_m",          "scale_error",
      "stroke_jitter_m",           "corner_cut_m",           "error_tolerance_m",
      "order_error_probability",   "backwards_probability",  "mid_stroke_lift_probability",
      "outside_touch_probability", "hesitation_probability", "noise_fraction",
      "tremor_amplitude_n"};
  return fields;
}

WriterProfile individual_profile(const WriterProfile& profile, const SubjectTraits& traits) {
  if (!traits.drawn) return profile;
  check_factor(traits.writing_speed_factor, "writing_speed_factor");
  check_factor(traits.spatial_error_factor, "spatial_error_factor");
  check_factor(traits.error_rate_factor, "error_rate_factor");
  check_factor(traits.motor_noise_factor, "motor_noise_factor");
  WriterProfile p = profile;
  p.writing_speed_m_s *= traits.writing_speed_factor;
  const double spatial = traits.spatial_error_factor;
  p.bias_offset_m *= spatial;
  // The validated range of the scale error is (-0.5, 0.5); a copy 45 % off is already no longer the
  // character.
  p.scale_error = std::clamp(p.scale_error * spatial, -0.45, 0.45);
  p.stroke_jitter_m *= spatial;
  p.corner_cut_m *= spatial;
  p.error_tolerance_m *= spatial;
  const auto rate = [&traits](double probability) {
    return std::min(probability * traits.error_rate_factor, 1.0);
  };
  p.order_error_probability = rate(p.order_error_probability);
  p.backwards_probability = rate(p.backwards_probability);
  p.mid_stroke_lift_probability = rate(p.mid_stroke_lift_probability);
  p.outside_touch_probability = rate(p.outside_touch_probability);
  p.hesitation_probability = rate(p.hesitation_probability);
  p.noise_fraction *= traits.motor_noise_factor;
  p.tremor_amplitude_n *= traits.motor_noise_factor;
  p.validate();
  return p;
}

}  // namespace calligraphy
