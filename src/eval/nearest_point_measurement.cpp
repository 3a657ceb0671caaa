#include "eval/nearest_point_measurement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "eval/lib2geom_nearest.hpp"
#include "eval/nearest_point_reference.hpp"
#include "eval/report_numbers.hpp"

namespace calligraphy::cli {

namespace {

constexpr double kOffThreshold = 1e-4;  // 0.1 mm, the table's failure threshold [m]
constexpr NearestPointMethod kMethods[] = {NearestPointMethod::exact, NearestPointMethod::newton,
                                           NearestPointMethod::subdivision};

// The paper's e for `subdivision`, relative to the element so no scenario is limited by it.
NearestPointOptions options_for(NearestPointMethod method, const StrokeElement& element) {
  NearestPointOptions options;
  options.method = method;
  if (method == NearestPointMethod::subdivision) {
    const double length = element.polygon_length();
    options.tolerance = length > 0.0 ? 1e-12 * length : 1e-12;
  }
  return options;
}

// Time per call of `distance_of(i)`, `repeats` calls timed together.
template <typename DistanceOf>
double time_query(const DistanceOf& distance_of, std::size_t i, int repeats, volatile double& sink) {
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) sink = sink + distance_of(i);
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(stop - start).count() / repeats;
}

// Errors and times of one solver, `distance_of(i)` being its distance for query i. Every solver sees
// the same queries in the same order; a query it throws on (std::nullopt from `checked_distance_of`)
// counts as an infinite error and is not timed.
template <typename DistanceOf, typename CheckedDistanceOf>
NearestPointRow measure_solver(NearestPointRow row, const std::vector<NearestPointQuery>& queries,
                               const std::vector<ReferenceNearest>& references, int repeats,
                               const DistanceOf& distance_of, const CheckedDistanceOf& checked_distance_of) {
  row.queries = static_cast<int>(queries.size());
  double error_sum = 0.0;
  int off = 0;
  std::vector<bool> failed(queries.size(), false);
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const std::optional<double> distance = checked_distance_of(i);
    double error = std::numeric_limits<double>::infinity();
    if (distance) {
      error = static_cast<double>(std::abs(static_cast<long double>(*distance) - references[i].distance));
    } else {
      failed[i] = true;
      ++row.failed_queries;
    }
    row.max_error_m = std::max(row.max_error_m, error);
    error_sum += error;
    if (error > kOffThreshold) ++off;
    const double length = queries[i].element.polygon_length();
    if (length > 0.0)
      row.max_error_over_length = std::max(row.max_error_over_length.value_or(0.0), error / length);
  }
  row.mean_error_m = error_sum / static_cast<double>(queries.size());
  row.frac_off_0p1mm = static_cast<double>(off) / static_cast<double>(queries.size());

  volatile double sink = 0.0;
  std::vector<double> times;
  times.reserve(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    if (!failed[i]) times.push_back(time_query(distance_of, i, repeats, sink));
  }
  std::sort(times.begin(), times.end());
  if (!times.empty()) {
    row.ns_median = nearest_rank(times, 0.5);
    row.ns_p99 = nearest_rank(times, 0.99);
  }
  return row;
}

NearestPointRow row_header(const char* method, int degree, const std::string& scenario) {
  NearestPointRow row;
  row.method = method;
  row.degree = degree;
  row.scenario = scenario;
  return row;
}

NearestPointRow measure_method(NearestPointMethod method, int degree, const std::string& scenario,
                               const std::vector<NearestPointQuery>& queries,
                               const std::vector<ReferenceNearest>& references, int repeats) {
  std::vector<NearestPointOptions> options;
  options.reserve(queries.size());
  for (const NearestPointQuery& query : queries) options.push_back(options_for(method, query.element));
  const auto distance_of = [&](std::size_t i) {
    return nearest_point(queries[i].element, queries[i].point, options[i]).distance;
  };
  const auto checked = [&](std::size_t i) { return std::optional<double>(distance_of(i)); };
  return measure_solver(row_header(method_name(method), degree, scenario), queries, references, repeats,
                        distance_of, checked);
}

// lib2geom's Geom::nearest_time on curves converted before the timing (as a caller would keep them
// for a stroke); the time includes evaluating the foot point and the distance.
NearestPointRow measure_lib2geom(int degree, const std::string& scenario,
                                 const std::vector<NearestPointQuery>& queries,
                                 const std::vector<ReferenceNearest>& references, int repeats) {
  NearestPointRow row = row_header(kLib2geomMethod, degree, scenario);
  if (!lib2geom_built()) {
    row.built = false;
    row.queries = static_cast<int>(queries.size());
    return row;
  }
  std::vector<Lib2geomCurve> curves;
  curves.reserve(queries.size());
  for (const NearestPointQuery& query : queries) curves.emplace_back(query.element);
  const auto distance_of = [&](std::size_t i) { return curves[i].nearest(queries[i].point).distance; };
  const auto checked = [&](std::size_t i) -> std::optional<double> {
    try {
      return distance_of(i);
    } catch (const Error&) {
      return std::nullopt;
    }
  };
  return measure_solver(std::move(row), queries, references, repeats, distance_of, checked);
}

// Through volatile floats: GCC 12 at -O2 dropped the plain double -> float -> double round trip in
// this file (it includes the __float128 reference), which made float look as precise as double.
Vec2 round_to_float(const Vec2& v) {
  const volatile float x = static_cast<float>(v.x());
  const volatile float y = static_cast<float>(v.y());
  return {static_cast<double>(x), static_cast<double>(y)};
}

// Max error of the exact method when the input passes through float first.
std::vector<PrecisionRow> measure_precision(const std::vector<NearestPointQuery>& queries,
                                            const std::vector<ReferenceNearest>& references, int degree) {
  PrecisionRow as_double{"double", degree, 0.0};
  PrecisionRow float_global{"float, global coordinates", degree, 0.0};
  PrecisionRow float_local{"float, relative to the first control point", degree, 0.0};
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const StrokeElement& element = queries[i].element;
    const Vec2& point = queries[i].point;
    StrokeElement global = element;
    StrokeElement local = element;
    for (int k = 0; k <= element.degree; ++k) {
      const auto index = static_cast<std::size_t>(k);
      global.control[index] = round_to_float(element.control[index]);
      local.control[index] = round_to_float(element.control[index] - element.start());
    }
    auto error_of = [&](const StrokeElement& e, const Vec2& p) {
      return static_cast<double>(
          std::abs(static_cast<long double>(nearest_point(e, p).distance) - references[i].distance));
    };
    as_double.max_error_m = std::max(as_double.max_error_m, error_of(element, point));
    float_global.max_error_m = std::max(float_global.max_error_m, error_of(global, round_to_float(point)));
    float_local.max_error_m =
        std::max(float_local.max_error_m, error_of(local, round_to_float(point - element.start())));
  }
  return {as_double, float_global, float_local};
}

}  // namespace

const char* method_name(NearestPointMethod method) {
  switch (method) {
    case NearestPointMethod::exact:
      return "exact";
    case NearestPointMethod::newton:
      return "newton";
    case NearestPointMethod::subdivision:
      return "subdivision";
  }
  return "unknown";
}

NearestPointMeasurement measure_nearest_point(const std::vector<NearestPointScenario>& scenarios,
                                              const MeasurementSettings& settings) {
  NearestPointMeasurement measurement;
  measurement.precision_scenario = "offset_1e2";
  for (std::size_t s = 0; s < scenarios.size(); ++s) {
    for (int degree = 1; degree <= kMaxElementDegree; ++degree) {
      std::seed_seq seeds{static_cast<std::uint32_t>(settings.seed),
                          static_cast<std::uint32_t>(settings.seed >> 32), static_cast<std::uint32_t>(s),
                          static_cast<std::uint32_t>(degree)};
      std::mt19937_64 random(seeds);
      const std::vector<NearestPointQuery> queries = scenarios[s].make(degree, settings.queries, random);
      if (queries.empty()) continue;
      std::vector<ReferenceNearest> references;
      references.reserve(queries.size());
      for (const NearestPointQuery& query : queries)
        references.push_back(reference_nearest_point(query.element, query.point));
      for (const NearestPointMethod method : kMethods) {
        measurement.rows.push_back(
            measure_method(method, degree, scenarios[s].name, queries, references, settings.timing_repeats));
      }
      measurement.rows.push_back(
          measure_lib2geom(degree, scenarios[s].name, queries, references, settings.timing_repeats));
      if (scenarios[s].name == measurement.precision_scenario) {
        for (PrecisionRow& row : measure_precision(queries, references, degree))
          measurement.precision.push_back(row);
      }
    }
  }
  return measurement;
}

}  // namespace calligraphy::cli
