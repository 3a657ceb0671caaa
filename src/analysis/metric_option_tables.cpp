// The parameter tables of the metrics' options (parameter_table.hpp): each real-valued field's name, unit,
// range and one line; the counts (`max_points`, `max_grid_points`) are checked beside them
// (input_checks.cpp).
#include <array>

#include "calligraphy/analysis/metrics.hpp"

namespace calligraphy {

namespace {

constexpr std::array kCurveFields{
    ParameterField<CurveComparisonOptions>{"reference_step_m", "m", kPositiveRange,
                                           "arc-length step of the resampled reference curve",
                                           &CurveComparisonOptions::reference_step_m},
};

constexpr std::array kKinematicsFields{
    ParameterField<KinematicsOptions>{"low_pass_cutoff_hz", "Hz", kNonNegativeRange,
                                      "cut-off of the Gaussian low-pass filter on the positions, 0 for none",
                                      &KinematicsOptions::low_pass_cutoff_hz},
    ParameterField<KinematicsOptions>{
        "peak_prominence", "", ParameterRange{.low = 0.0, .high = 1.0, .low_open = true, .high_open = true},
        "rise and fall of a velocity peak as a share of the maximum speed",
        &KinematicsOptions::peak_prominence},
};

constexpr std::array kMetricsFields{
    ParameterField<MetricsOptions>{"tube_radius_m", "m", kNonNegativeRange,
                                   "radius of the tolerance tube around the reference stroke",
                                   &MetricsOptions::tube_radius_m},
};

}  // namespace

std::span<const ParameterField<CurveComparisonOptions>>
ParameterTable<CurveComparisonOptions>::fields() noexcept {
  return kCurveFields;
}

std::span<const ParameterField<KinematicsOptions>> ParameterTable<KinematicsOptions>::fields() noexcept {
  return kKinematicsFields;
}

std::span<const ParameterField<MetricsOptions>> ParameterTable<MetricsOptions>::fields() noexcept {
  return kMetricsFields;
}

}  // namespace calligraphy
