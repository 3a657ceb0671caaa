#pragma once
// Accuracy and speed of the nearest-point methods on the scenarios of nearest_point_scenarios.hpp,
// measured against the high-precision reference of nearest_point_reference.hpp.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/nearest_point.hpp"
#include "eval/nearest_point_scenarios.hpp"

namespace calligraphy::cli {

/// One row of the table: one method on one degree of one scenario.
struct NearestPointRow {
  std::string method;
  /// false for the lib2geom method in a build without lib2geom: nothing was measured.
  bool built = true;
  int degree = 0;
  std::string scenario;
  int queries = 0;
  double ns_median = 0.0;       ///< median time per query [ns]
  double ns_p99 = 0.0;          ///< 99th percentile of the time per query [ns]
  double max_error_m = 0.0;     ///< max |distance - reference distance| [m]
  double mean_error_m = 0.0;    ///< mean of the same [m]
  double frac_off_0p1mm = 0.0;  ///< share of queries whose distance is off by more than 1e-4 m
  /// max of error / control-polygon length over the queries with a non-zero length (dimensionless);
  /// empty when every element has zero length.
  std::optional<double> max_error_over_length;
  /// Queries the method threw on (only lib2geom can); counted with an infinite error and left out of
  /// the times.
  int failed_queries = 0;
};

/// The float-versus-double comparison: max distance error of the exact method when the input is
/// first rounded to float, in global coordinates or relative to the stroke's first control point.
struct PrecisionRow {
  std::string input;  ///< "double", "float, global coordinates", "float, local origin"
  int degree = 0;
  double max_error_m = 0.0;
};

struct NearestPointMeasurement {
  std::vector<NearestPointRow> rows;
  std::vector<PrecisionRow> precision;  ///< on the scenario `precision_scenario`
  std::string precision_scenario;
};

struct MeasurementSettings {
  int queries = 1000;       ///< queries per scenario and degree
  std::uint64_t seed = 1;   ///< seed of the random scenarios
  int timing_repeats = 16;  ///< calls per query timed together (the clock's overhead is shared)
};

/// The method names used in the table: "exact", "newton", "subdivision".
const char* method_name(NearestPointMethod method);

/// The name of lib2geom's Geom::nearest_time in the table (src/eval/lib2geom_nearest.hpp).
inline constexpr const char* kLib2geomMethod = "lib2geom";

/// Measures every method, and lib2geom's Geom::nearest_time (a row that is not `built` when this
/// build has no lib2geom), on every degree of every scenario with queries.
NearestPointMeasurement measure_nearest_point(const std::vector<NearestPointScenario>& scenarios,
                                              const MeasurementSettings& settings);

}  // namespace calligraphy::cli
