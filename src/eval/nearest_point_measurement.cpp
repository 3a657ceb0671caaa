#include "eval/nearest_point_measurement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "eval/nearest_point_reference.hpp"

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

double percentile(std::vector<double> values, double fraction) {
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

// Time per call of one query, `repeats` calls timed together.
double time_query(const NearestPointQuery& query, const NearestPointOptions& options, int repeats,
                  volatile double& sink) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) sink = sink + nearest_point(query.element, query.point, options).distance;
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(stop - start).count() / repeats;
}

NearestPointRow measure_method(NearestPointMethod method, int degree, const std::string& scenario,
                               const std::vector<NearestPointQuery>& queries,
                               const std::vector<ReferenceNearest>& references, int repeats) {
  NearestPointRow row;
  row.method = method_name(method);
  row.degree = degree;
  row.scenario = scenario;
  row.queries = static_cast<int>(queries.size());
  double error_sum = 0.0;
  int off = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const NearestPointOptions options = options_for(method, queries[i].element);
    const NearestPoint result = nearest_point(queries[i].element, queries[i].point, options);
    const auto error =
        static_cast<double>(std::abs(static_cast<long double>(result.distance) - references[i].distance));
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
  for (const NearestPointQuery& query : queries) {
    times.push_back(time_query(query, options_for(method, query.element), repeats, sink));
  }
  row.ns_median = percentile(times, 0.5);
  row.ns_p99 = percentile(times, 0.99);
  return row;
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
      if (scenarios[s].name == measurement.precision_scenario) {
        for (PrecisionRow& row : measure_precision(queries, references, degree))
          measurement.precision.push_back(row);
      }
    }
  }
  return measurement;
}

}  // namespace calligraphy::cli
