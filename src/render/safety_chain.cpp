#include "calligraphy/render/safety_chain.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {
namespace {

// Shortens `v` to at most `limit`, keeping its direction; true when it did. A finite force beyond 1e154 N has
// a squared norm that overflows: its direction is then taken from the vector scaled by its largest component,
// so that it is clamped, not zeroed.
bool shorten(Vec3& v, double limit) noexcept {
  const double n = v.norm();
  if (n <= limit) return false;
  if (std::isinf(n) && v.allFinite()) {
    const Vec3 direction = v / v.cwiseAbs().maxCoeff();
    v = direction * (limit / direction.norm());
    return true;
  }
  v *= n > 0.0 ? limit / n : 0.0;
  return true;
}

}  // namespace

namespace {

using SafetyField = ParameterField<SafetyChainParameters>;
using S = SafetyChainParameters;
// An order of magnitude above the peak force of every device this library knows (the Phantom Desktop's
// 7.9 N is the largest): a larger limit is a typing error, not a limit.
constexpr ParameterRange kForce{.high = 100.0};
// Under the Nyquist frequency of the fastest servo loop (100 kHz); WholeTrial also holds it under its own.
constexpr ParameterRange kCutoff{.high = 50000.0, .high_open = true};
// The RMS estimate's time constant: at most a day, the longest trial (TrialSpec::max_duration_s); a slower
// estimate never moves within a trial.
constexpr ParameterRange kTimeConstant{.high = 86400.0, .low_open = true};

// In declaration order; a stage at 0 is off, except the peak force and the time constant.
constexpr std::array kSafetyFields{
    SafetyField{"max_force_n", "N", kForce,
                "peak clamp; 0 = the device's max force (the renderer fills it in)", &S::max_force_n},
    SafetyField{"max_continuous_force_n", "N", kForce,
                "continuous-force limit; 0 = the device's under a renderer, off in a bare chain",
                &S::max_continuous_force_n},
    SafetyField{"continuous_time_constant_s", "s", kTimeConstant, "tau of the RMS (thermal) force estimate",
                &S::continuous_time_constant_s},
    SafetyField{"start_ramp_n_per_s", "N/s", kNonNegativeRange, "force ramp after start or reset; 0 = off",
                &S::start_ramp_n_per_s},
    SafetyField{"max_force_change_n_per_tick", "N", kNonNegativeRange, "per-tick force change limit; 0 = off",
                &S::max_force_change_n_per_tick},
    SafetyField{"low_pass_cutoff_hz", "Hz", kCutoff, "first-order low-pass cutoff; 0 = off",
                &S::low_pass_cutoff_hz},
};

}  // namespace

std::span<const ParameterField<SafetyChainParameters>>
ParameterTable<SafetyChainParameters>::fields() noexcept {
  return kSafetyFields;
}

void SafetyChainParameters::validate() const {
  check_parameters(*this);
  if (max_force_n > 0.0 && max_continuous_force_n > max_force_n) {
    throw InvalidArgument(
        "SafetyChainParameters.max_continuous_force_n = " + shortest_decimal(max_continuous_force_n) +
        " must not exceed max_force_n = " + shortest_decimal(max_force_n));
  }
}

void check_low_pass_cutoff(double low_pass_cutoff_hz, double rate_hz) {
  // A first-order low-pass at or above the loop's Nyquist frequency filters nothing it can sample.
  if (low_pass_cutoff_hz > 0.0 && low_pass_cutoff_hz >= 0.5 * rate_hz) {
    std::string message = "low_pass_cutoff_hz = ";
    message.append(shortest_decimal(low_pass_cutoff_hz))
        .append(" Hz must be under half the servo rate (rate_hz / 2 = ")
        .append(shortest_decimal(0.5 * rate_hz))
        .append(" Hz); 0 = off");
    throw InvalidArgument(message);
  }
}

SafetyChain::SafetyChain(const SafetyChainParameters& parameters, double rate_hz) : parameters_(parameters) {
  parameters_.validate();
  if (!(parameters_.max_force_n > 0.0)) {  // 0 stands for the device's peak, which only a renderer knows
    throw InvalidArgument(
        "SafetyChain: SafetyChainParameters.max_force_n = 0 N: a chain needs its peak force > 0");
  }
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0)) {
    throw InvalidArgument("SafetyChain: rate_hz = " + detail::rate_text(rate_hz) + " must be finite and > 0");
  }
  check_low_pass_cutoff(parameters_.low_pass_cutoff_hz, rate_hz);
  period_s_ = 1.0 / rate_hz;
  low_pass_alpha_ = parameters_.low_pass_cutoff_hz > 0.0
                        ? 1.0 - std::exp(-2.0 * std::numbers::pi * parameters_.low_pass_cutoff_hz * period_s_)
                        : 1.0;
  rms_beta_ = 1.0 - std::exp(-period_s_ / parameters_.continuous_time_constant_s);
}

void SafetyChain::reset() noexcept {
  filtered_ = Vec3::Zero();
  last_output_ = Vec3::Zero();
  mean_square_n2_ = 0.0;
  time_since_start_s_ = 0.0;
}

double SafetyChain::rms_force_n() const noexcept { return std::sqrt(mean_square_n2_); }

SafetyResult SafetyChain::apply(const Vec3& force_n) noexcept {
  SafetyResult result;
  time_since_start_s_ += period_s_;
  // 1. Non-finite: zero at once; the filter restarts from zero so no NaN survives in the state.
  if (!force_n.allFinite()) {
    ++non_finite_count_;
    filtered_ = Vec3::Zero();
    last_output_ = Vec3::Zero();
    mean_square_n2_ += rms_beta_ * (0.0 - mean_square_n2_);
    result.limits = safety_non_finite;
    return result;
  }
  // 2. Low-pass.
  Vec3 f = force_n;
  if (parameters_.low_pass_cutoff_hz > 0.0) {
    filtered_ += low_pass_alpha_ * (force_n - filtered_);
    f = filtered_;
    result.limits |= safety_low_pass;
  }
  // 3. Continuous-force limit from the RMS (thermal) estimate.
  const double continuous = parameters_.max_continuous_force_n;
  if (continuous > 0.0) {
    const double rms = std::sqrt(mean_square_n2_);
    const double knee = 0.8 * continuous;
    const double share = std::clamp((rms - knee) / (continuous - knee), 0.0, 1.0);
    const double allowed = parameters_.max_force_n + share * (continuous - parameters_.max_force_n);
    if (shorten(f, allowed)) result.limits |= safety_continuous;
  }
  // 4. Peak clamp.
  if (shorten(f, parameters_.max_force_n)) result.limits |= safety_peak;
  // 5. Start ramp.
  if (parameters_.start_ramp_n_per_s > 0.0 &&
      shorten(f, parameters_.start_ramp_n_per_s * time_since_start_s_)) {
    result.limits |= safety_start_ramp;
  }
  // 6. Per-tick change limit along the change's own direction.
  if (parameters_.max_force_change_n_per_tick > 0.0) {
    Vec3 change = f - last_output_;
    if (shorten(change, parameters_.max_force_change_n_per_tick)) {
      f = last_output_ + change;
      result.limits |= safety_rate;
    }
  }
  last_output_ = f;
  mean_square_n2_ += rms_beta_ * (f.squaredNorm() - mean_square_n2_);
  result.force_n = f;
  return result;
}

}  // namespace calligraphy
