#include "calligraphy/render/safety_chain.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {
namespace {

// Shortens `v` to at most `limit`, keeping its direction; true when it did.
bool shorten(Vec3& v, double limit) noexcept {
  const double n = v.norm();
  if (n <= limit) return false;
  v *= n > 0.0 ? limit / n : 0.0;
  return true;
}

}  // namespace

void SafetyChainParameters::validate() const {
  const auto check = [](double value, const char* name, bool positive) {
    if (!std::isfinite(value) || value < 0.0 || (positive && value == 0.0)) {
      throw InvalidArgument(std::string("SafetyChainParameters.") + name + " = " + std::to_string(value) +
                            (positive ? " must be finite and > 0" : " must be finite and >= 0"));
    }
  };
  check(max_force_n, "max_force_n", true);
  check(max_continuous_force_n, "max_continuous_force_n", false);
  check(continuous_time_constant_s, "continuous_time_constant_s", true);
  check(start_ramp_n_per_s, "start_ramp_n_per_s", false);
  check(max_force_change_n_per_tick, "max_force_change_n_per_tick", false);
  check(low_pass_cutoff_hz, "low_pass_cutoff_hz", false);
  if (max_continuous_force_n > max_force_n) {
    throw InvalidArgument(
        "SafetyChainParameters.max_continuous_force_n = " + std::to_string(max_continuous_force_n) +
        " must not exceed max_force_n = " + std::to_string(max_force_n));
  }
}

SafetyChain::SafetyChain(const SafetyChainParameters& parameters, double rate_hz) : parameters_(parameters) {
  parameters_.validate();
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0)) {
    throw InvalidArgument("SafetyChain: rate_hz = " + detail::rate_text(rate_hz) + " must be finite and > 0");
  }
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
