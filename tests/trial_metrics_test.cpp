#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/core/errors.hpp"
#include "parameter_table_walk.hpp"

using namespace calligraphy;

namespace {

std::vector<Vec2> segment_points(const Vec2& a, const Vec2& b, std::size_t count) {
  std::vector<Vec2> out;
  for (std::size_t i = 0; i < count; ++i)
    out.push_back(a + (b - a) * (static_cast<double>(i) / static_cast<double>(count - 1)));
  return out;
}

// Minimum-jerk movement (Flash & Hogan 1985) of length `length_m` along x in `duration_s`, sampled at
// `rate_hz`: x(tau) = L (10 tau^3 - 15 tau^4 + 6 tau^5), tau = t / T.
void minimum_jerk(double length_m, double duration_s, double rate_hz, std::vector<double>& t,
                  std::vector<Vec2>& p, double start_s = 0.0, const Vec2& origin = Vec2::Zero()) {
  const auto n = static_cast<std::size_t>(std::llround(duration_s * rate_hz));
  for (std::size_t i = 0; i <= n; ++i) {
    const double tau = static_cast<double>(i) / static_cast<double>(n);
    t.push_back(start_s + tau * duration_s);
    p.push_back(origin +
                Vec2(length_m * (10 * std::pow(tau, 3) - 15 * std::pow(tau, 4) + 6 * std::pow(tau, 5)), 0.0));
  }
}

}  // namespace

TEST_CASE("Frechet and DTW of identical polylines are 0", "[metrics]") {
  std::vector<Vec2> curve;
  for (int i = 0; i < 200; ++i) curve.emplace_back(0.001 * i, 0.01 * std::sin(0.05 * i));
  CHECK(discrete_frechet_distance(curve, curve) == 0.0);
  CHECK(dtw_mean_distance(curve, curve) == 0.0);
}

TEST_CASE("Frechet and DTW of two parallel segments at distance d equal d", "[metrics]") {
  const double d = 1.5e-3;
  const auto a = segment_points({0.0, 0.0}, {0.05, 0.0}, 101);
  const auto b = segment_points({0.0, d}, {0.05, d}, 101);
  // Any coupling pairs points at least d apart, and the diagonal one pairs every point at exactly d.
  CHECK(discrete_frechet_distance(a, b) == Approx(d).epsilon(1e-12));
  CHECK(dtw_mean_distance(a, b) == Approx(d).epsilon(1e-12));
  // Symmetric in its arguments.
  const auto c = segment_points({0.0, d}, {0.05, d}, 37);
  CHECK(discrete_frechet_distance(a, c) == Approx(discrete_frechet_distance(c, a)).epsilon(1e-12));
  CHECK(dtw_mean_distance(a, c) == Approx(dtw_mean_distance(c, a)).epsilon(1e-12));
}

TEST_CASE("Discrete Frechet is the worst pair of the best coupling, not of the nearest points", "[metrics]") {
  // b runs along a, then comes back: a monotone coupling must pair b's last point (0, 0) with a's last
  // point (1, 0), so the distance is 1, although every point of b lies on a.
  const std::vector<Vec2> a{{0.0, 0.0}, {1.0, 0.0}};
  const std::vector<Vec2> b{{0.0, 0.0}, {1.0, 0.0}, {0.0, 0.0}};
  CHECK(discrete_frechet_distance(a, b) == Approx(1.0));
  // DTW: pairs (0,0)-(0,0), (1,0)-(1,0), (1,0)-(0,0): sum 1 over 3 pairs.
  CHECK(dtw_mean_distance(a, b) == Approx(1.0 / 3.0));
}

TEST_CASE("Frechet and DTW refuse unbounded work and bad input", "[metrics]") {
  const auto big = segment_points({0.0, 0.0}, {1.0, 0.0}, 5000);
  CHECK_THROWS_AS(discrete_frechet_distance(big, big), InvalidArgument);
  CHECK_THROWS_AS(dtw_mean_distance(big, big), InvalidArgument);
  CHECK_THROWS_AS(discrete_frechet_distance({}, big), InvalidArgument);
  std::vector<Vec2> bad{{0.0, 0.0}, {NAN, 0.0}};
  CHECK_THROWS_WITH(dtw_mean_distance(bad, bad), Catch::Contains("point 1"));
}

TEST_CASE("compare_curves bounds a 100,000-sample trace and keeps the distance", "[metrics]") {
  const double d = 1e-3;
  const std::vector<StrokeElement> reference{StrokeElement::line({0.0, 0.0}, {0.05, 0.0})};
  const auto written = segment_points({0.0, d}, {0.05, d}, 100'000);
  const CurveDistances distances = compare_curves(written, reference);
  // Reference points are at most half a step from any written point's foot, so the coupled distance is
  // at most sqrt(d^2 + (step / 2)^2); it is at least d (the first points).
  const double step = CurveComparisonOptions{}.reference_step_m;
  CHECK(distances.frechet_m >= d * (1 - 1e-12));
  CHECK(distances.frechet_m <= std::hypot(d, step / 2) * (1 + 1e-9));
  CHECK(distances.dtw_m >= d * (1 - 1e-12));
  CHECK(distances.dtw_m <= std::hypot(d, step / 2) * (1 + 1e-9));
  // Written backwards against the reversed reference: the same distances.
  const std::vector<Vec2> reversed(written.rbegin(), written.rend());
  CHECK(compare_curves(reversed, reference, {}, true).frechet_m == Approx(distances.frechet_m).epsilon(1e-9));
  CHECK(compare_curves(reversed, reference).frechet_m > 0.04);  // start coupled to the far end
}

TEST_CASE("resample_by_arc_length spaces points evenly and keeps the ends", "[metrics]") {
  const std::vector<Vec2> l{{0.0, 0.0}, {3.0, 0.0}, {3.0, 1.0}};  // length 4
  const auto r = resample_by_arc_length(l, 5);
  REQUIRE(r.size() == 5);
  CHECK(r[0] == l[0]);
  CHECK(r[1].isApprox(Vec2(1.0, 0.0)));
  CHECK(r[3].isApprox(Vec2(3.0, 0.0)));
  CHECK(r[4] == l[2]);
  CHECK_THROWS_AS(resample_by_arc_length(l, 1), InvalidArgument);
}

TEST_CASE("Deviation: mean, max, RMS and tube share of known distances", "[metrics]") {
  const std::vector<StrokeElement> reference{StrokeElement::line({0.0, 0.0}, {0.1, 0.0})};
  // Distances 0, 1, 2, 3 mm above the segment, and one beyond its end, 4 mm from the end point.
  const std::vector<Vec2> samples{{0.01, 0.0}, {0.02, 0.001}, {0.03, -0.002}, {0.04, 0.003}, {0.104, 0.0}};
  const DeviationSummary s = deviation_summary(samples, reference, 2.5e-3);
  CHECK(s.samples == 5);
  CHECK(s.mean_m == Approx(2e-3));
  CHECK(s.max_m == Approx(4e-3));
  CHECK(s.rms_m == Approx(std::sqrt((0.0 + 1 + 4 + 9 + 16) / 5.0) * 1e-3));
  CHECK(s.outside_tube_share == Approx(2.0 / 5.0));
  // The same as the per-sample definition.
  CHECK(deviation_from_stroke_m(reference, samples[4]) == Approx(4e-3));
  CHECK_THROWS_AS(deviation_summary({}, reference, 1e-3), InvalidArgument);
  CHECK_THROWS_AS(deviation_summary(samples, reference, -1.0), InvalidArgument);
}

TEST_CASE("Deviation summaries pool sample by sample", "[metrics]") {
  const std::vector<StrokeElement> reference{StrokeElement::line({0.0, 0.0}, {0.1, 0.0})};
  const std::vector<Vec2> first{{0.01, 0.001}, {0.02, 0.001}};
  const std::vector<Vec2> second{{0.01, 0.004}};
  std::vector<Vec2> all = first;
  all.insert(all.end(), second.begin(), second.end());
  const std::vector<DeviationSummary> parts{deviation_summary(first, reference, 2e-3),
                                            deviation_summary(second, reference, 2e-3)};
  const DeviationSummary pooled = pool_deviation_summaries(parts);
  const DeviationSummary direct = deviation_summary(all, reference, 2e-3);
  CHECK(pooled.samples == 3);
  CHECK(pooled.mean_m == Approx(direct.mean_m));  // 2 mm, not the mean of the means (2.5 mm)
  CHECK(pooled.rms_m == Approx(direct.rms_m));
  CHECK(pooled.max_m == direct.max_m);
  CHECK(pooled.outside_tube_share == Approx(direct.outside_tube_share));
  const std::vector<DeviationSummary> mixed{parts[0], deviation_summary(second, reference, 1e-3)};
  CHECK_THROWS_AS(pool_deviation_summaries(mixed), InvalidArgument);
}

// Minimum-jerk closed forms. With x = L s(tau), s = 10 tau^3 - 15 tau^4 + 6 tau^5, the jerk is
// x''' = (L / T^3) s'''(tau), s''' = 60 - 360 tau + 360 tau^2 = 60 (1 - 6 tau + 6 tau^2). Then
// integral_0^T (x''')^2 dt = (L^2 / T^5) 3600 integral_0^1 (1 - 6 tau + 6 tau^2)^2 dtau
//   = (L^2 / T^5) 3600 (1 - 6 + 16 - 18 + 36/5) = 720 L^2 / T^5,
// so the normalised jerk sqrt(0.5 * 720 L^2/T^5 * T^5 / L^2) = sqrt(360) = 18.974, whatever L and T.
// The speed L s'(tau) / T = 30 L tau^2 (1 - tau)^2 / T has one peak, at tau = 1/2.
TEST_CASE("A minimum-jerk movement has one velocity peak and normalised jerk sqrt(360)", "[metrics]") {
  for (const auto& [length, duration] : {std::pair{0.03, 0.6}, std::pair{0.05, 1.5}}) {
    std::vector<double> t;
    std::vector<Vec2> p;
    minimum_jerk(length, duration, 1000.0, t, p);
    KinematicsOptions unfiltered;
    unfiltered.low_pass_cutoff_hz = 0.0;
    const StrokeKinematics exact = stroke_kinematics(t, p, unfiltered);
    INFO("L = " << length << " m, T = " << duration << " s");
    CHECK(exact.writing_time_s == Approx(duration));
    CHECK(exact.path_length_m == Approx(length));
    CHECK(exact.mean_speed_m_per_s == Approx(length / duration));
    CHECK(exact.velocity_peaks == 1);
    // Finite differences at 1 kHz; the jerk's jumps at both ends are smeared over a few samples.
    CHECK(exact.normalised_jerk == Approx(std::sqrt(360.0)).epsilon(0.01));
    // The 10 Hz filter takes off the jerk's power above 10 Hz (its jumps at both ends): lower, not far.
    const StrokeKinematics filtered = stroke_kinematics(t, p);
    CHECK(filtered.velocity_peaks == 1);
    CHECK(filtered.normalised_jerk < exact.normalised_jerk);
    CHECK(filtered.normalised_jerk == Approx(std::sqrt(360.0)).epsilon(0.1));
  }
}

TEST_CASE("Two minimum-jerk movements one after the other have two velocity peaks", "[metrics]") {
  std::vector<double> t;
  std::vector<Vec2> p;
  minimum_jerk(0.02, 0.5, 1000.0, t, p);
  minimum_jerk(0.02, 0.5, 1000.0, t, p, 0.501, Vec2(0.02, 0.0));
  CHECK(stroke_kinematics(t, p).velocity_peaks == 2);
  // A sampling rate of 100 Hz does not change the count.
  std::vector<double> t_slow;
  std::vector<Vec2> p_slow;
  for (std::size_t i = 0; i < t.size(); i += 10) {
    t_slow.push_back(t[i]);
    p_slow.push_back(p[i]);
  }
  CHECK(stroke_kinematics(t_slow, p_slow).velocity_peaks == 2);
}

TEST_CASE("Kinematics stay bounded for extreme timestamps", "[metrics]") {
  // 100,000 samples 1000 s apart, and 100,000 samples within 1 us: the grid is bounded by the sample count
  // and the filter's resolution, so both return finite values.
  std::vector<double> t;
  std::vector<Vec2> p;
  for (int i = 0; i < 100'000; ++i) {
    t.push_back(1000.0 * i);
    p.emplace_back(1e-4 * std::sin(0.001 * i), 1e-4 * i);
  }
  const StrokeKinematics slow = stroke_kinematics(t, p);
  CHECK(std::isfinite(slow.normalised_jerk));
  CHECK(slow.velocity_peaks >= 1);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = 1e-11 * static_cast<double>(i);
  const StrokeKinematics fast = stroke_kinematics(t, p);
  CHECK(std::isfinite(fast.normalised_jerk));
  CHECK(fast.velocity_peaks == 1);  // the whole movement lies within one filter width: one bump
}

TEST_CASE("Kinematics reject bad samples, naming the index", "[metrics]") {
  std::vector<double> t{0.0, 0.1, 0.05};
  std::vector<Vec2> p{{0.0, 0.0}, {0.01, 0.0}, {0.02, 0.0}};
  CHECK_THROWS_WITH(stroke_kinematics(t, p), Catch::Contains("sample 2"));
  t = {0.0, 0.1, 0.2};
  p[1].x() = INFINITY;
  CHECK_THROWS_WITH(stroke_kinematics(t, p), Catch::Contains("sample 1"));
  p = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
  CHECK_THROWS_AS(stroke_kinematics(t, p), InvalidArgument);  // the pen does not move
  p = {{0.0, 0.0}, {0.01, 0.0}, {0.02, 0.0}};
  KinematicsOptions bad;
  bad.peak_prominence = 0.0;
  CHECK_THROWS_AS(stroke_kinematics(t, p, bad), InvalidArgument);
}

TEST_CASE("The metrics' option tables: defaults in range, each bound refused by name", "[metrics]") {
  const std::vector<StrokeElement> reference{StrokeElement::line(Vec2(0, 0), Vec2(0.03, 0))};
  std::vector<double> t;
  std::vector<Vec2> p;
  minimum_jerk(0.03, 0.6, 200.0, t, p);
  check_table_through<CurveComparisonOptions>(
      [&](const CurveComparisonOptions& options) { (void)compare_curves(p, reference, options); });
  check_table_through<KinematicsOptions>(
      [&](const KinematicsOptions& options) { (void)stroke_kinematics(t, p, options); });
  check_table_through<MetricsOptions>(
      [&](const MetricsOptions& options) { (void)stroke_writing_metrics(t, p, reference, options); });
  // The counts beside the tables, named the same way.
  CurveComparisonOptions one_point;
  one_point.max_points = 1;
  CHECK_THROWS_WITH(compare_curves(p, reference, one_point),
                    Catch::Contains("CurveComparisonOptions.max_points = 1"));
  KinematicsOptions small_grid;
  small_grid.max_grid_points = 15;
  CHECK_THROWS_WITH(stroke_kinematics(t, p, small_grid),
                    Catch::Contains("KinematicsOptions.max_grid_points = 15"));
}
