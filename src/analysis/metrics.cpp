#include "calligraphy/analysis/metrics.hpp"

#include <string>

#include "analysis/input_checks.hpp"
#include "analysis/segment_metrics.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

StrokeWritingMetrics trial_detail::stroke_writing_metrics(const StrokeKinematics& kinematics,
                                                          std::span<const Vec2> positions_m,
                                                          std::span<const StrokeElement> reference_m,
                                                          const MetricsOptions& options,
                                                          bool reference_reversed) {
  StrokeWritingMetrics m;
  m.kinematics = kinematics;
  m.deviation = deviation_summary(positions_m, reference_m, options.tube_radius_m);
  m.curves = compare_curves(positions_m, reference_m, options.curves, reference_reversed);
  return m;
}

StrokeWritingMetrics stroke_writing_metrics(std::span<const double> times_s,
                                            std::span<const Vec2> positions_m,
                                            std::span<const StrokeElement> reference_m,
                                            const MetricsOptions& options, bool reference_reversed) {
  if (times_s.size() != positions_m.size()) {
    throw InvalidArgument("stroke_writing_metrics: " + std::to_string(times_s.size()) + " times but " +
                          std::to_string(positions_m.size()) + " positions");
  }
  trial_detail::require_valid_options(options);  // every option named by its table before any work
  return trial_detail::stroke_writing_metrics(stroke_kinematics(times_s, positions_m, options.kinematics),
                                              positions_m, reference_m, options, reference_reversed);
}

}  // namespace calligraphy
