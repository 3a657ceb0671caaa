#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "analysis/curve_distances.hpp"
#include "analysis/input_checks.hpp"
#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

std::vector<Vec2> without_consecutive_repeats(std::span<const Vec2> points) {
  std::vector<Vec2> out;
  out.reserve(points.size());
  for (const Vec2& p : points) {
    if (out.empty() || p != out.back()) out.push_back(p);
  }
  return out;
}

}  // namespace

std::vector<Vec2> resample_by_arc_length(std::span<const Vec2> polyline, std::size_t count) {
  trial_detail::require_finite_points(polyline, "resample_by_arc_length", "the polyline");
  if (count < 2)
    throw InvalidArgument("resample_by_arc_length: count " + std::to_string(count) + " is below 2");
  double total = 0.0;
  for (std::size_t i = 1; i < polyline.size(); ++i) total += (polyline[i] - polyline[i - 1]).norm();
  // Finite points can be farther apart than a double reaches (1e308 m apart): no point of such a polyline can
  // be placed by its arc length.
  if (!std::isfinite(total))
    throw InvalidArgument(
        "resample_by_arc_length: the polyline's length overflows a double (its points are "
        "too far apart to measure)");
  std::vector<Vec2> out;
  out.reserve(count);
  out.push_back(polyline.front());
  if (!(total > 0.0)) {
    out.resize(count, polyline.front());
    return out;
  }
  // Walk the polyline once: `walked` is the arc length at the start of segment `i`.
  std::size_t i = 1;
  double walked = 0.0;
  for (std::size_t k = 1; k + 1 < count; ++k) {
    const double target = total * static_cast<double>(k) / static_cast<double>(count - 1);
    double length = (polyline[i] - polyline[i - 1]).norm();
    while (walked + length < target && i + 1 < polyline.size()) {
      walked += length;
      ++i;
      length = (polyline[i] - polyline[i - 1]).norm();
    }
    const double f = length > 0.0 ? std::clamp((target - walked) / length, 0.0, 1.0) : 0.0;
    out.push_back(polyline[i - 1] + f * (polyline[i] - polyline[i - 1]));
  }
  out.push_back(polyline.back());
  return out;
}

std::vector<Vec2> reference_polyline_m(std::span<const StrokeElement> reference_m, double step_m,
                                       std::size_t max_points) {
  if (reference_m.empty()) throw InvalidArgument("reference_polyline_m: the reference stroke has no element");
  if (!std::isfinite(step_m) || step_m <= 0.0) {
    throw InvalidArgument("reference_polyline_m: step " + shortest_decimal(step_m) +
                          " m is not a finite length > 0");
  }
  if (max_points < 2)
    throw InvalidArgument("reference_polyline_m: max_points " + std::to_string(max_points) + " is below 2");
  std::vector<Vec2> dense;
  dense.reserve(reference_m.size() * kReferenceChordsPerElement + 1);
  dense.push_back(reference_m.front().start());
  double length = 0.0;
  for (const StrokeElement& element : reference_m) {
    for (int k = 1; k <= kReferenceChordsPerElement; ++k) {
      dense.push_back(element.point(static_cast<double>(k) / kReferenceChordsPerElement));
      length += (dense.back() - dense[dense.size() - 2]).norm();
    }
  }
  trial_detail::require_finite_points(dense, "reference_polyline_m", "the reference stroke");
  const double intervals = std::ceil(length / step_m);
  const std::size_t count = intervals + 1.0 >= static_cast<double>(max_points)
                                ? max_points
                                : std::max<std::size_t>(2, static_cast<std::size_t>(intervals) + 1);
  return resample_by_arc_length(dense, count);
}

CurveDistances compare_curves(std::span<const Vec2> samples_m, std::span<const StrokeElement> reference_m,
                              const CurveComparisonOptions& options, bool reference_reversed) {
  trial_detail::require_valid_options(options);
  trial_detail::require_finite_points(samples_m, "compare_curves", "the written samples");
  std::vector<Vec2> reference =
      reference_polyline_m(reference_m, options.reference_step_m, options.max_points);
  if (reference_reversed) std::reverse(reference.begin(), reference.end());
  std::vector<Vec2> written = without_consecutive_repeats(samples_m);
  if (written.size() > options.max_points) written = resample_by_arc_length(written, options.max_points);
  return trial_detail::frechet_and_dtw(written, reference, "compare_curves");
}

}  // namespace calligraphy
