#pragma once
/// \file velocity_filter.hpp
/// Velocity from sampled positions: a backward difference smoothed by a first-order low-pass,
///   v_raw = (x_k - x_{k-1}) / dt,   v_k = v_{k-1} + a (v_raw - v_{k-1}),   a = dt / (dt + 1 / (2 pi f_c)).
/// Why: encoder quantisation (about 0.05 mm on an Omni) differentiated at 1 kHz is noise of about
/// 0.05 m/s; a 50 Hz cut-off removes most of it while adding only about 3 ms of lag.

#include <numbers>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::devices {

class VelocityFilter {
 public:
  /// `cutoff_hz` [Hz] > 0: the -3 dB frequency of the smoothing.
  explicit VelocityFilter(double cutoff_hz) noexcept
      : time_constant_s_(1.0 / (2.0 * std::numbers::pi * cutoff_hz)) {}

  /// Feeds a position [m] sampled at `time_s` [s]; returns the velocity estimate [m/s]. The first
  /// sample returns zero; a sample whose time does not advance returns the previous estimate.
  Vec3 update(const Vec3& position_m, double time_s) noexcept {
    if (!has_sample_) {
      has_sample_ = true;
    } else {
      const double dt = time_s - last_time_s_;
      if (!(dt > 0.0)) return velocity_m_s_;
      const Vec3 raw = (position_m - last_position_m_) / dt;
      velocity_m_s_ += (dt / (dt + time_constant_s_)) * (raw - velocity_m_s_);
    }
    last_position_m_ = position_m;
    last_time_s_ = time_s;
    return velocity_m_s_;
  }
  void reset() noexcept {
    has_sample_ = false;
    velocity_m_s_ = Vec3::Zero();
  }

 private:
  double time_constant_s_;
  Vec3 last_position_m_ = Vec3::Zero();
  Vec3 velocity_m_s_ = Vec3::Zero();
  double last_time_s_ = 0.0;
  bool has_sample_ = false;
};

}  // namespace calligraphy::devices
