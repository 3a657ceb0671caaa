// Time per nearest-point query, per method and degree, on random curves in a 50 mm box with the
// query within 5 mm (scenario random_near of `calligraphy bench nearest`) and on the real strokes of
// the embedded characters (scenario corpus, degrees 1-3), and per tracker update on a point moving
// along a curve. Run a Release build: build/bin/nearest_point_bench
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "eval/nearest_point_scenarios.hpp"

namespace {

using calligraphy::NearestPointMethod;
using calligraphy::Vec2;

constexpr int kQueries = 1024;

std::vector<calligraphy::cli::NearestPointQuery> near_queries(int degree) {
  std::mt19937_64 random(static_cast<std::uint64_t>(degree));
  return calligraphy::cli::random_curve_queries(degree, kQueries, random, 0.05, Vec2::Zero(), 0.0, 0.005);
}

void nearest_point_method(benchmark::State& state, NearestPointMethod method) {
  const auto queries = near_queries(static_cast<int>(state.range(0)));
  calligraphy::NearestPointOptions options;
  options.method = method;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& query = queries[i];
    benchmark::DoNotOptimize(calligraphy::nearest_point(query.element, query.point, options));
    i = (i + 1) % queries.size();
  }
}

// Scenario `corpus`: every fitted element of the embedded characters, P within 5 mm.
void nearest_point_corpus(benchmark::State& state, NearestPointMethod method) {
  std::vector<calligraphy::cli::NearestPointQuery> queries;
  for (const auto& scenario : calligraphy::cli::nearest_point_scenarios()) {
    std::mt19937_64 random(static_cast<std::uint64_t>(state.range(0)));
    if (scenario.name == "corpus")
      queries = scenario.make(static_cast<int>(state.range(0)), kQueries, random);
  }
  if (queries.empty()) {
    state.SkipWithError("no corpus element of this degree");
    return;
  }
  calligraphy::NearestPointOptions options;
  options.method = method;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& query = queries[i];
    benchmark::DoNotOptimize(calligraphy::nearest_point(query.element, query.point, options));
    i = (i + 1) % queries.size();
  }
}

void segment(benchmark::State& state) {
  const auto queries = near_queries(1);
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& query = queries[i];
    benchmark::DoNotOptimize(calligraphy::nearest_point_on_segment(query.element.control[0],
                                                                   query.element.control[1], query.point));
    i = (i + 1) % queries.size();
  }
}

// A pen moving along a cubic at 1 kHz, 2 mm off the curve, 0.1 mm per tick.
void tracker_update(benchmark::State& state) {
  const Vec2 points[4] = {{0.0, 0.0}, {0.02, 0.04}, {0.04, -0.01}, {0.05, 0.03}};
  const auto element = calligraphy::StrokeElement::bezier(points, 4);
  std::vector<Vec2> path;
  for (int tick = 0; tick < 1000; ++tick) {
    const double t = tick / 999.0;
    const Vec2 tangent = element.unit_tangent(t);
    path.push_back(element.point(t) + 0.002 * Vec2(-tangent.y(), tangent.x()));
  }
  calligraphy::NearestPointTracker tracker;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tracker.update(element, path[i]));
    i = (i + 1) % path.size();
  }
}

}  // namespace

BENCHMARK_CAPTURE(nearest_point_method, exact, NearestPointMethod::exact)->DenseRange(1, 4);
BENCHMARK_CAPTURE(nearest_point_method, newton, NearestPointMethod::newton)->DenseRange(1, 4);
BENCHMARK_CAPTURE(nearest_point_method, subdivision, NearestPointMethod::subdivision)->DenseRange(1, 4);
BENCHMARK_CAPTURE(nearest_point_corpus, exact, NearestPointMethod::exact)->DenseRange(1, 3);
BENCHMARK_CAPTURE(nearest_point_corpus, newton, NearestPointMethod::newton)->DenseRange(1, 3);
BENCHMARK_CAPTURE(nearest_point_corpus, subdivision, NearestPointMethod::subdivision)->DenseRange(1, 3);
BENCHMARK(segment);
BENCHMARK(tracker_update);

BENCHMARK_MAIN();
