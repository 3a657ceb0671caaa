#pragma once
/// \file safety_chain.hpp
/// The safety chain between the force law and the device (Wang, Zhang & Yao 2006, section 6, name force steps
/// as a source of instability). A value type applied once per servo tick, in this order:
///   1. non-finite check: a NaN/Inf force gives zero force at once, sets `SafetyLimit::non_finite`
///      and is counted (the only stage allowed to step the force: an invalid force is never smoothed);
///   2. low-pass (optional): first-order, cutoff f_c [Hz], y += (1 - exp(-2 pi f_c T)) (x - y);
///   3. continuous-force limit: an RMS estimate of the commanded force, the square root of an
///      exponential moving average of |F|^2 with time constant tau [s] (a first-order thermal model of
///      the motors: heating goes with current squared); the allowed magnitude is the peak force while
///      the estimate is below 80 % of the continuous force and falls linearly to the continuous force
///      as the estimate reaches it, so a sustained demand settles at the continuous force;
///   4. clamp to the peak force [N], keeping the direction;
///   5. start ramp: |F| <= ramp_rate * (time since start or reset) [N/s];
///   6. per-tick change limit: |F(k) - F(k-1)| <= max_step [N per tick]; a larger change is shortened
///      along its own direction (a vector rate limit).
/// Stages 3-6 only shrink the force towards the previous output or zero, so the output satisfies
/// every limit at once. Servo path: noexcept, no allocation, deterministic.
#include <cstdint>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/core/parameter_table.hpp"

namespace calligraphy {

/// Parameters of the chain. A stage set to 0 is off (except the peak force, which is required).
struct SafetyChainParameters {
  /// Peak clamp [N] >= 0; 0 = the device's max force, filled in by the renderer (a bare `SafetyChain`
  /// needs it > 0).
  double max_force_n = 0.0;
  /// Continuous-force limit [N] >= 0; 0 = the device's under a renderer, off in a bare chain.
  double max_continuous_force_n = 0.0;
  double continuous_time_constant_s = 10.0;   ///< tau of the RMS (thermal) estimate [s], > 0
  double start_ramp_n_per_s = 20.0;           ///< force ramp after start or reset [N/s], 0 = off
  double max_force_change_n_per_tick = 0.25;  ///< per-tick change limit [N per tick], 0 = off
  double low_pass_cutoff_hz = 0.0;            ///< first-order low-pass cutoff [Hz], 0 = off

  /// Throws InvalidArgument naming the field when a value is outside its table's range
  /// (`ParameterTable<SafetyChainParameters>`: negative or not finite, `continuous_time_constant_s` not
  /// positive), or when the continuous force exceeds a peak force that is set.
  void validate() const;
};

/// Throws InvalidArgument "low_pass_cutoff_hz = F Hz must be under half the servo rate (rate_hz / 2 = R Hz);
/// 0 = off" when the low-pass is on at or above the Nyquist frequency of a loop at `rate_hz` [Hz] (a
/// first-order low-pass there filters nothing the loop samples). The one check of that rule: `SafetyChain`,
/// `RendererOptions::validate` and a whole trial's safety part (trial/whole_trial.hpp) apply it.
void check_low_pass_cutoff(double low_pass_cutoff_hz, double rate_hz);

/// The fields of SafetyChainParameters (parameter_table.hpp): the one definition of their units and ranges.
template <>
struct ParameterTable<SafetyChainParameters> {
  static constexpr std::string_view name = "SafetyChainParameters";
  [[nodiscard]] static std::span<const ParameterField<SafetyChainParameters>> fields() noexcept;
};

/// Bits of `SafetyResult::limits`: which stages changed the force this tick.
enum SafetyLimit : std::uint8_t {
  safety_none = 0,
  safety_non_finite = 1U << 0,  ///< input not finite: zero force
  safety_low_pass = 1U << 1,    ///< low-pass on (set every tick it is on)
  safety_continuous = 1U << 2,  ///< continuous-force limit shortened the force
  safety_peak = 1U << 3,        ///< peak clamp shortened the force
  safety_start_ramp = 1U << 4,  ///< start ramp shortened the force
  safety_rate = 1U << 5,        ///< per-tick change limit shortened the change
};

/// What one tick of the chain did.
struct SafetyResult {
  Vec3 force_n = Vec3::Zero();        ///< force to command [N], finite
  std::uint8_t limits = safety_none;  ///< SafetyLimit bits
};

class SafetyChain {
 public:
  /// `rate_hz`: servo rate [Hz], > 0. Throws InvalidArgument for bad parameters or rate, and a low-pass on at
  /// or above half the rate (check_low_pass_cutoff).
  SafetyChain(const SafetyChainParameters& parameters, double rate_hz);

  /// One tick: the force law's force in [N], the force to command out.
  SafetyResult apply(const Vec3& force_n) noexcept;
  /// Back to the start: previous output zero, ramp restarts, RMS estimate and filter cleared.
  void reset() noexcept;

  [[nodiscard]] const SafetyChainParameters& parameters() const noexcept { return parameters_; }
  [[nodiscard]] double rate_hz() const noexcept { return 1.0 / period_s_; }
  /// Non-finite inputs seen since construction (not cleared by reset).
  [[nodiscard]] std::uint64_t non_finite_count() const noexcept { return non_finite_count_; }
  /// The RMS force estimate of stage 3 [N].
  [[nodiscard]] double rms_force_n() const noexcept;
  /// The last output [N].
  [[nodiscard]] const Vec3& last_output() const noexcept { return last_output_; }

 private:
  SafetyChainParameters parameters_;
  double period_s_;
  double low_pass_alpha_;  // 1 - exp(-2 pi f_c T), 1 when off
  double rms_beta_;        // 1 - exp(-T / tau)
  Vec3 filtered_ = Vec3::Zero();
  Vec3 last_output_ = Vec3::Zero();
  double mean_square_n2_ = 0.0;
  double time_since_start_s_ = 0.0;
  std::uint64_t non_finite_count_ = 0;
};

}  // namespace calligraphy
