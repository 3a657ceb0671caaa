#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "analysis/durations.hpp"
#include "analysis/input_checks.hpp"
#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

constexpr double kGridPointsPerInterval = 16.0;

void check_samples(std::span<const double> times_s, std::span<const Vec2> positions_m) {
  if (times_s.size() != positions_m.size()) {
    throw InvalidArgument("stroke_kinematics: " + std::to_string(times_s.size()) + " times but " +
                          std::to_string(positions_m.size()) + " positions");
  }
  if (times_s.size() < 2) throw InvalidArgument("stroke_kinematics: fewer than 2 samples");
  for (std::size_t i = 0; i < times_s.size(); ++i) {
    if (!std::isfinite(times_s[i]) || !positions_m[i].allFinite()) {
      throw InvalidArgument("stroke_kinematics: sample " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && times_s[i] < times_s[i - 1]) {
      throw InvalidArgument("stroke_kinematics: time goes backwards at sample " + std::to_string(i) + " (" +
                            shortest_decimal(times_s[i]) + " s after " + shortest_decimal(times_s[i - 1]) +
                            " s)");
    }
  }
}

// Standard deviation [s] of the Gaussian whose frequency response exp(-2 pi^2 sigma^2 f^2) is 1/sqrt(2)
// at the cut-off: sigma = sqrt(ln 2) / (2 pi f_c).
double gaussian_sigma_s(double cutoff_hz) {
  return std::sqrt(std::numbers::ln2) / (2.0 * std::numbers::pi * cutoff_hz);
}

// The samples linearly interpolated at t0 + (k - padding) h for k in [0, count + 2 padding), the pen resting
// at its first and last position outside [t0, t0 + (count - 1) h].
std::vector<Vec2> uniform_grid(std::span<const double> t, std::span<const Vec2> p, double step_s,
                               std::size_t count, std::size_t padding) {
  std::vector<Vec2> grid(count + 2 * padding);
  std::size_t i = 0;
  for (std::size_t k = 0; k < grid.size(); ++k) {
    if (k < padding) {
      grid[k] = p.front();
    } else if (k >= padding + count - 1) {
      grid[k] = p.back();
    } else {
      const double time = t.front() + static_cast<double>(k - padding) * step_s;
      while (i + 2 < t.size() && t[i + 1] <= time) ++i;
      const double span = t[i + 1] - t[i];
      const double f = span > 0.0 ? std::clamp((time - t[i]) / span, 0.0, 1.0) : 1.0;
      grid[k] = p[i] + f * (p[i + 1] - p[i]);
    }
  }
  return grid;
}

// Convolution with a Gaussian truncated at 4 sigma, values beyond the ends held (the pen at rest).
std::vector<Vec2> gaussian_filtered(const std::vector<Vec2>& signal, double sigma_s, double step_s) {
  const auto half_width = static_cast<std::ptrdiff_t>(std::ceil(4.0 * sigma_s / step_s));
  std::vector<double> weights(static_cast<std::size_t>(2 * half_width + 1));
  double total = 0.0;
  for (std::ptrdiff_t j = -half_width; j <= half_width; ++j) {
    const double x = static_cast<double>(j) * step_s / sigma_s;
    total += weights[static_cast<std::size_t>(j + half_width)] = std::exp(-0.5 * x * x);
  }
  for (double& w : weights) w /= total;
  // The held ends written out, so that the taps need no bounds check.
  const auto width = static_cast<std::size_t>(half_width);
  std::vector<Vec2> held(signal.size() + 2 * width, signal.front());
  std::copy(signal.begin(), signal.end(), held.begin() + half_width);
  std::fill(held.end() - half_width, held.end(), signal.back());
  std::vector<Vec2> out(signal.size(), Vec2::Zero());
  for (std::size_t k = 0; k < signal.size(); ++k) {
    Vec2 sum = Vec2::Zero();
    for (std::size_t j = 0; j < weights.size(); ++j) sum += weights[j] * held[k + j];
    out[k] = sum;
  }
  return out;
}

// Peaks of the speed with hysteresis: a peak is counted once the speed has risen by `threshold` above
// the last trough and then fallen by `threshold` below the highest value since (or the signal ends).
int count_peaks(const std::vector<double>& speed, double threshold) {
  int peaks = 0;
  bool rising = true;
  double trough = speed.empty() ? 0.0 : speed.front();
  double crest = trough;
  for (const double v : speed) {
    if (rising) {
      trough = std::min(trough, v);
      if (v - trough >= threshold) {
        rising = false;
        crest = v;
      }
    } else {
      crest = std::max(crest, v);
      if (crest - v >= threshold) {
        ++peaks;
        rising = true;
        trough = v;
      }
    }
  }
  return rising ? peaks : peaks + 1;
}

}  // namespace

StrokeKinematics stroke_kinematics(std::span<const double> times_s, std::span<const Vec2> positions_m,
                                   const KinematicsOptions& options) {
  trial_detail::require_valid_options(options);
  check_samples(times_s, positions_m);
  StrokeKinematics k;
  // The samples' span as the grid and the jerk take it; the writing time reported is that span in whole
  // nanoseconds, as every time of the metrics record is (docs/metrics.md), so n ticks of 1 ms read n ms (a
  // span under half a nanosecond is kept as it is).
  const double span_s = times_s.back() - times_s.front();
  if (!(span_s > 0.0)) throw InvalidArgument("stroke_kinematics: the samples span no time");
  const double rounded_s = analysis::whole_nanoseconds(span_s);
  k.writing_time_s = rounded_s > 0.0 ? rounded_s : span_s;
  for (std::size_t i = 1; i < positions_m.size(); ++i)
    k.path_length_m += (positions_m[i] - positions_m[i - 1]).norm();
  if (!(k.path_length_m > 0.0)) throw InvalidArgument("stroke_kinematics: the pen does not move");
  k.mean_speed_m_per_s = k.path_length_m / k.writing_time_s;

  const bool filtered = options.low_pass_cutoff_hz > 0.0;
  const double sigma_s = filtered ? gaussian_sigma_s(options.low_pass_cutoff_hz) : 0.0;
  // The grid step: the mean sampling interval, kept within [sigma / 16, sigma / 4] when filtering so that
  // the kernel is resolved by 9 to 129 taps. The grid is capped at kGridPointsPerInterval points per
  // sampling interval and at max_grid_points (the step grows instead), which bounds the work by the
  // number of samples whatever the timestamps.
  const double sample_count = static_cast<double>(times_s.size());
  double step_s = span_s / (sample_count - 1.0);
  if (filtered) step_s = std::clamp(step_s, sigma_s / 16.0, sigma_s / 4.0);
  const double needed = std::max(1.0, std::ceil(span_s / step_s));
  const double intervals = std::min({needed, static_cast<double>(options.max_grid_points - 1),
                                     kGridPointsPerInterval * (sample_count - 1.0)});
  if (intervals < needed) step_s = span_s / intervals;
  // The grid covers [t0, t0 + intervals * step], at least the samples' span; later points hold the end.
  const auto count = static_cast<std::size_t>(intervals) + 1;
  // Rest before and after: as far as the kernel spreads the movement, plus the stencils' reach.
  const std::size_t padding =
      (filtered ? static_cast<std::size_t>(std::ceil(4.0 * sigma_s / step_s)) : 0) + 3;
  std::vector<Vec2> grid = uniform_grid(times_s, positions_m, step_s, count, padding);
  if (filtered) grid = gaussian_filtered(grid, sigma_s, step_s);

  std::vector<double> speed(grid.size() - 2);
  for (std::size_t i = 1; i + 1 < grid.size(); ++i)
    speed[i - 1] = (grid[i + 1] - grid[i - 1]).norm() / (2.0 * step_s);
  const double top_speed = *std::max_element(speed.begin(), speed.end());
  k.velocity_peaks = count_peaks(speed, options.peak_prominence * top_speed);

  double jerk_squared_integral = 0.0;
  const double h3 = 2.0 * step_s * step_s * step_s;
  for (std::size_t i = 2; i + 2 < grid.size(); ++i) {
    const Vec2 jerk = (grid[i + 2] - 2.0 * grid[i + 1] + 2.0 * grid[i - 1] - grid[i - 2]) / h3;
    jerk_squared_integral += jerk.squaredNorm() * step_s;
  }
  const double t = span_s;
  k.normalised_jerk =
      std::sqrt(0.5 * jerk_squared_integral * std::pow(t, 5) / (k.path_length_m * k.path_length_m));
  return k;
}

}  // namespace calligraphy
