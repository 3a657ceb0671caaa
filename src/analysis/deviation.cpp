#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/nearest_point.hpp"

namespace calligraphy {
namespace {

std::string point_text(const Vec2& p) {
  return "(" + shortest_decimal(p.x()) + ", " + shortest_decimal(p.y()) + ")";
}

}  // namespace

double deviation_from_stroke_m(std::span<const StrokeElement> reference_m, const Vec2& point_m) {
  if (reference_m.empty())
    throw InvalidArgument("deviation_from_stroke_m: the reference stroke has no element");
  if (!point_m.allFinite())
    throw InvalidArgument("deviation_from_stroke_m: point " + point_text(point_m) + " is not finite");
  return distance_to_elements(reference_m, point_m);
}

DeviationPool::DeviationPool(double tube_radius_m) : tube_radius_m_(tube_radius_m) {
  if (!std::isfinite(tube_radius_m) || tube_radius_m < 0.0) {
    throw InvalidArgument("DeviationPool: tube radius " + shortest_decimal(tube_radius_m) +
                          " m is not a finite length >= 0");
  }
}

void DeviationPool::add(double deviation_m) {
  if (!std::isfinite(deviation_m) || deviation_m < 0.0) {
    throw InvalidArgument("DeviationPool::add: deviation " + shortest_decimal(deviation_m) +
                          " m is not a finite length >= 0");
  }
  ++count_;
  if (deviation_m > tube_radius_m_) ++outside_;
  sum_ += deviation_m;
  sum_squares_ += deviation_m * deviation_m;
  max_ = std::max(max_, deviation_m);
}

void DeviationPool::merge(const DeviationPool& other) {
  if (other.tube_radius_m_ != tube_radius_m_) {
    throw InvalidArgument("DeviationPool::merge: tube radii differ (" + shortest_decimal(tube_radius_m_) +
                          " m and " + shortest_decimal(other.tube_radius_m_) + " m)");
  }
  count_ += other.count_;
  outside_ += other.outside_;
  sum_ += other.sum_;
  sum_squares_ += other.sum_squares_;
  max_ = std::max(max_, other.max_);
}

DeviationSummary DeviationPool::summary() const {
  if (count_ == 0) throw InvalidArgument("DeviationPool::summary: no deviation was added");
  const double n = static_cast<double>(count_);
  DeviationSummary s;
  s.samples = count_;
  s.mean_m = sum_ / n;
  s.max_m = max_;
  s.rms_m = std::sqrt(sum_squares_ / n);
  s.tube_radius_m = tube_radius_m_;
  s.outside_tube_share = static_cast<double>(outside_) / n;
  return s;
}

DeviationSummary pool_deviation_summaries(std::span<const DeviationSummary> parts) {
  if (parts.empty()) throw InvalidArgument("pool_deviation_summaries: no summary to pool");
  DeviationSummary pooled;
  pooled.tube_radius_m = parts.front().tube_radius_m;
  double sum = 0.0;
  double sum_squares = 0.0;
  double outside = 0.0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const DeviationSummary& part = parts[i];
    if (part.samples == 0)
      throw InvalidArgument("pool_deviation_summaries: summary " + std::to_string(i) + " has no sample");
    if (part.tube_radius_m != pooled.tube_radius_m) {
      throw InvalidArgument("pool_deviation_summaries: summary " + std::to_string(i) + " has tube radius " +
                            shortest_decimal(part.tube_radius_m) + " m, the first " +
                            shortest_decimal(pooled.tube_radius_m) + " m");
    }
    const double n = static_cast<double>(part.samples);
    pooled.samples += part.samples;
    sum += part.mean_m * n;
    sum_squares += part.rms_m * part.rms_m * n;
    outside += part.outside_tube_share * n;
    pooled.max_m = std::max(pooled.max_m, part.max_m);
  }
  const double n = static_cast<double>(pooled.samples);
  pooled.mean_m = sum / n;
  pooled.rms_m = std::sqrt(sum_squares / n);
  pooled.outside_tube_share = outside / n;
  return pooled;
}

DeviationSummary deviation_summary(std::span<const Vec2> samples_m,
                                   std::span<const StrokeElement> reference_m, double tube_radius_m) {
  if (samples_m.empty()) throw InvalidArgument("deviation_summary: no sample");
  DeviationPool pool(tube_radius_m);
  for (std::size_t i = 0; i < samples_m.size(); ++i) {
    if (!samples_m[i].allFinite()) {
      throw InvalidArgument("deviation_summary: sample " + std::to_string(i) + " " +
                            point_text(samples_m[i]) + " is not finite");
    }
    pool.add(deviation_from_stroke_m(reference_m, samples_m[i]));
  }
  return pool.summary();
}

}  // namespace calligraphy
