#pragma once
/// \file subject_traits.hpp
/// How one simulated subject differs from the others of its profile (docs/writer.md, "Individual
/// differences"): its baseline skill (how large its spatial errors are, how fast it writes, how often it
/// errs), its motor noise and its two-state learning rates and retention, each drawn once per subject from a
/// log-normal distribution whose median is the profile's value, so that the profile stays the population's
/// typical member. The draws are a function of the subject's seed alone (`subject_seed`, the subject's id),
/// so the same subject is the same person in `session run`, `session cohort` and Python's cohort.
///
/// Spreads: writing speed 0.2 (log-SD), spatial error 0.3, error rates 0.3, motor noise 0.3, learning rates
/// 0.5, retention time constants 0.3. Where each comes from (measured between-subject spreads and the
/// assumptions): docs/writer.md and docs/references.md.
#include <cstdint>

#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// The log-normal spreads (standard deviation of the natural log, dimensionless) of a subject's traits
/// about its profile. All 0: every subject is its profile (no individual differences). Ranges:
/// `ParameterTable<SubjectSpread>`, the one definition.
struct SubjectSpread {
  double writing_speed = 0.2;   ///< log-SD of the writing speed factor
  double spatial_error = 0.3;   ///< log-SD of bias, scale error, jitter, corner cut and error tolerance
  double error_rate = 0.3;      ///< log-SD of the error probabilities (order, backwards, lifts, ...)
  double motor_noise = 0.3;     ///< log-SD of the force noise fraction and the tremor amplitude
  double learning_rate = 0.5;   ///< log-SD of the two-state learning rates B_f and B_s (one factor)
  double retention_time = 0.3;  ///< log-SD of the retention time constants 1 / (1 - A) (one factor)
  /// Throws InvalidArgument naming the field for a spread that is negative, not finite or above 2.
  void validate() const;
};

template <>
struct ParameterTable<SubjectSpread> {
  static constexpr std::string_view name = "SubjectSpread";
  [[nodiscard]] static std::span<const ParameterField<SubjectSpread>> fields() noexcept;
};
/// The table's schema (schema.hpp).
template <>
struct SchemaOf<SubjectSpread> {
  static const Schema& get();
};

/// One subject's traits: factors on its profile's fields (1 = the profile) and its own two-state rates.
struct SubjectTraits {
  bool drawn = false;                 ///< false: the profile itself (individual differences off)
  double writing_speed_factor = 1.0;  ///< multiplies `writing_speed_m_s`, > 0
  /// Multiplies `bias_offset_m`, `scale_error`, `stroke_jitter_m`, `corner_cut_m` and `error_tolerance_m`
  /// (the scale error kept below 0.45), > 0.
  double spatial_error_factor = 1.0;
  /// Multiplies the error probabilities (order, backwards, lift, outside touch, hesitation; at most 1), > 0.
  double error_rate_factor = 1.0;
  double motor_noise_factor = 1.0;  ///< multiplies `noise_fraction` and `tremor_amplitude_n`, > 0
  TwoStateRates learning{};         ///< the subject's two-state rates, per trial
};

/// The traits of the subject with `subject_seed` (SessionSetup::writer_seed): log-normal draws about the
/// profile with `spread`, in a fixed order from a stream of the seed's own (independent of the trials'
/// seeds). Deterministic. Throws what `SubjectSpread::validate` throws.
[[nodiscard]] SubjectTraits draw_subject_traits(std::uint64_t subject_seed, const SubjectSpread& spread = {});

/// `profile` with `traits` applied (see SubjectTraits), validated; `profile` itself when `!traits.drawn`.
/// Throws InvalidArgument for a factor that is not finite and > 0.
[[nodiscard]] WriterProfile individual_profile(const WriterProfile& profile, const SubjectTraits& traits);

/// The numeric fields (`set_writer_parameter` keys) `individual_profile` changes, in order.
[[nodiscard]] const std::vector<std::string>& individual_profile_fields();

}  // namespace calligraphy
