#pragma once
/// \file writer_learning.hpp
/// Learning across repetitions, a model (docs/writer.md, "Learning"): after each repetition the bias and
/// the error rates of a profile shrink towards the skilled writer's, by an exponential law of practice
/// (Heathcote, Brown & Mewhort 2000): q(n+1) = q* + (q(n) - q*) exp(-lambda w), with lambda the profile's
/// `learning_rate` and w in [0, 1] the feedback the repetition gave on that quantity. It is a model for
/// scripting experiments, not a finding; its feedback weights are assumptions stated in the docs.
#include <cstddef>

#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// What one repetition gave the writer.
struct RepetitionOutcome {
  /// Haptic feedback of the repetition, in [0, 1]: 0 without guidance, the gain of fading guidance, 1
  /// for fixed or replayed guidance.
  double guidance_share = 0.0;
  std::size_t out_of_order_attempts = 0;  ///< strokes the writer started out of order
  std::size_t refused_out_of_order = 0;   ///< of which the display refused (the writer felt it)
  std::size_t backwards_attempts = 0;     ///< strokes the writer started from their end
  std::size_t refused_backwards = 0;      ///< of which the display refused

  /// The outcome of a repetition whose writer kept `log`, under guidance of share `guidance_share`.
  [[nodiscard]] static RepetitionOutcome from_log(const WriterLog& log, double guidance_share);
  /// Throws InvalidArgument when the share is outside [0, 1] or a refused count exceeds its attempts.
  void validate() const;
};

/// Share of the shape feedback (bias) that comes from seeing the trace alone, without guidance: an
/// assumption (docs/writer.md).
inline constexpr double kVisualFeedbackShare = 0.5;

/// The profile for the next repetition. With `learning_rate` 0 the profile is returned unchanged.
/// Bias (offset, |scale error|, jitter) and the fluency errors (lifts, touches outside, hesitations)
/// move towards the skilled profile's values with w = s + (1 - s) g (s = kVisualFeedbackShare, g the
/// guidance share); the order and direction error rates shrink only by what the writer was shown: w =
/// the share of its out-of-order (backwards) attempts that were refused, or g when it made none.
/// Values already below the skilled writer's stay. Throws InvalidArgument for a bad profile or outcome.
[[nodiscard]] WriterProfile next_repetition_profile(const WriterProfile& profile,
                                                    const RepetitionOutcome& outcome);

}  // namespace calligraphy
