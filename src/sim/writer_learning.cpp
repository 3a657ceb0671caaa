#include "calligraphy/sim/writer_learning.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// One step of the exponential law of practice towards `asymptote` with feedback weight `weight`; a
// value already at or below the asymptote stays.
double practise(double value, double asymptote, double rate, double weight) {
  if (value <= asymptote) return value;
  return asymptote + (value - asymptote) * std::exp(-rate * weight);
}

double refused_share(std::size_t attempts, std::size_t refused, double guidance_share) {
  return attempts == 0 ? guidance_share : static_cast<double>(refused) / static_cast<double>(attempts);
}

}  // namespace

RepetitionOutcome RepetitionOutcome::from_log(const WriterLog& log, double guidance_share) {
  RepetitionOutcome outcome;
  outcome.guidance_share = guidance_share;
  outcome.out_of_order_attempts = log.out_of_order_attempts();
  outcome.refused_out_of_order = log.refused_out_of_order();
  outcome.backwards_attempts = log.backwards_attempts();
  outcome.refused_backwards = log.refused_backwards();
  return outcome;
}

void RepetitionOutcome::validate() const {
  if (!(guidance_share >= 0.0 && guidance_share <= 1.0)) {
    throw InvalidArgument("RepetitionOutcome.guidance_share = " + shortest_decimal(guidance_share) +
                          " must be in [0, 1]");
  }
  if (refused_out_of_order > out_of_order_attempts || refused_backwards > backwards_attempts) {
    throw InvalidArgument("RepetitionOutcome: more refused attempts than attempts (out of order " +
                          std::to_string(refused_out_of_order) + " of " +
                          std::to_string(out_of_order_attempts) + ", backwards " +
                          std::to_string(refused_backwards) + " of " + std::to_string(backwards_attempts) +
                          ")");
  }
}

WriterProfile next_repetition_profile(const WriterProfile& profile, const RepetitionOutcome& outcome) {
  profile.validate();
  outcome.validate();
  if (profile.learning_rate == 0.0) return profile;
  const WriterProfile expert = WriterProfile::skilled();
  const double rate = profile.learning_rate;
  const double shape = kVisualFeedbackShare + (1.0 - kVisualFeedbackShare) * outcome.guidance_share;
  WriterProfile next = profile;
  next.bias_offset_m = practise(profile.bias_offset_m, expert.bias_offset_m, rate, shape);
  next.scale_error =
      std::copysign(practise(std::abs(profile.scale_error), std::abs(expert.scale_error), rate, shape),
                    profile.scale_error);
  next.stroke_jitter_m = practise(profile.stroke_jitter_m, expert.stroke_jitter_m, rate, shape);
  next.mid_stroke_lift_probability =
      practise(profile.mid_stroke_lift_probability, expert.mid_stroke_lift_probability, rate, shape);
  next.outside_touch_probability =
      practise(profile.outside_touch_probability, expert.outside_touch_probability, rate, shape);
  next.hesitation_probability =
      practise(profile.hesitation_probability, expert.hesitation_probability, rate, shape);
  next.order_error_probability = practise(
      profile.order_error_probability, expert.order_error_probability, rate,
      refused_share(outcome.out_of_order_attempts, outcome.refused_out_of_order, outcome.guidance_share));
  next.backwards_probability =
      practise(profile.backwards_probability, expert.backwards_probability, rate,
               refused_share(outcome.backwards_attempts, outcome.refused_backwards, outcome.guidance_share));
  next.validate();
  return next;
}

}  // namespace calligraphy
