// NearestPointTracker: hysteresis between equal minima, following a moving point, reset, bad input.
#include "calligraphy/model/nearest_point_tracker.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <utility>

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/core/errors.hpp"

using calligraphy::NearestPoint;
using calligraphy::NearestPointTracker;
using calligraphy::NearestPointTrackerOptions;
using calligraphy::StrokeElement;
using calligraphy::Vec2;

namespace {

constexpr double kMm = 1e-3;

// y = 20 - x^2 / 20 mm for x in [-20, 20] mm: apex (0, 20) mm with its centre of curvature at
// (0, 10) mm. From (0, 5) mm the nearest points are (+-10, 15) mm, at t = 0.25 and 0.75, equally far.
StrokeElement symmetric_arc() {
  const Vec2 points[3] = {Vec2(-20, 0) * kMm, Vec2(0, 40) * kMm, Vec2(20, 0) * kMm};
  return StrokeElement::bezier(points, 3);
}

}  // namespace

TEST_CASE("The tracker does not flip between two equal minima", "[nearest_point][tracker]") {
  const StrokeElement arc = symmetric_arc();
  // The pen sits on the axis with 0.1 um of noise across it: the global minimum alternates sides.
  auto pen = [](int tick) { return Vec2((tick % 2 == 0 ? 1e-7 : -1e-7), 5 * kMm); };
  int global_flips = 0;
  double previous_global_t = calligraphy::nearest_point(arc, pen(0)).t;
  for (int tick = 1; tick < 200; ++tick) {
    const double t = calligraphy::nearest_point(arc, pen(tick)).t;
    if (std::abs(t - previous_global_t) > 0.25) ++global_flips;
    previous_global_t = t;
  }
  REQUIRE(global_flips > 100);  // the test is meaningful: recomputing globally flips every tick

  for (const int period : {1, 16}) {
    NearestPointTrackerOptions options;
    options.global_check_period = period;
    NearestPointTracker tracker(options);
    const double first_t = tracker.update(arc, pen(0)).t;
    int flips = 0;
    for (int tick = 1; tick < 200; ++tick) {
      const NearestPoint result = tracker.update(arc, pen(tick));
      if (std::abs(result.t - first_t) > 0.01) ++flips;
      CHECK(result.distance == Approx(std::sqrt(200.0) * kMm).margin(2e-7));  // the pen moves 1e-7 m
    }
    INFO("global check every " << period << " ticks");
    CHECK(flips == 0);
  }
}

TEST_CASE("The tracker switches once another minimum is nearer by more than the hysteresis",
          "[nearest_point][tracker]") {
  const StrokeElement arc = symmetric_arc();
  NearestPointTrackerOptions options;
  options.global_check_period = 8;
  NearestPointTracker tracker(options);
  REQUIRE(tracker.update(arc, Vec2(-1 * kMm, 5 * kMm)).t < 0.5);  // left minimum
  // Move to the right: the left minimum survives as a local one (Newton stays) but the right one
  // is now millimetres nearer; the periodic global check must move the foot within 8 ticks.
  const Vec2 right(3 * kMm, 5 * kMm);
  const NearestPoint exact = calligraphy::nearest_point(arc, right);
  REQUIRE(exact.t > 0.5);
  NearestPoint result;
  for (int tick = 0; tick < options.global_check_period; ++tick) result = tracker.update(arc, right);
  CHECK(result.t == Approx(exact.t).margin(1e-9));
  CHECK(result.distance == Approx(exact.distance).epsilon(1e-12));
}

TEST_CASE("The tracker follows a point moving along a curve", "[nearest_point][tracker]") {
  const Vec2 points[4] = {Vec2(0, 0), Vec2(20, 40) * kMm, Vec2(40, -10) * kMm, Vec2(50, 30) * kMm};
  const StrokeElement curve = StrokeElement::bezier(points, 4);
  NearestPointTracker tracker;
  int mismatches = 0;
  for (int tick = 0; tick < 1000; ++tick) {
    // 1 mm off the curve on alternating sides' fixed normal, 1 s along the stroke at 1 kHz.
    const double t = tick / 999.0;
    const Vec2 tangent = curve.unit_tangent(t);
    const Vec2 pen = curve.point(t) + 1 * kMm * Vec2(-tangent.y(), tangent.x());
    const NearestPoint tracked = tracker.update(curve, pen);
    const NearestPoint exact = calligraphy::nearest_point(curve, pen);
    REQUIRE(std::isfinite(tracked.distance));
    if (std::abs(tracked.distance - exact.distance) > 1e-9) ++mismatches;
    CHECK(tracked.t == Approx(t).margin(1e-6));
  }
  CHECK(mismatches == 0);
}

TEST_CASE("reset() makes the next update search globally, bad input leaves the state alone",
          "[nearest_point][tracker]") {
  const StrokeElement arc = symmetric_arc();
  NearestPointTracker tracker;
  CHECK_FALSE(tracker.tracking());
  const NearestPoint before = tracker.update(arc, Vec2(-1 * kMm, 5 * kMm));
  CHECK(tracker.tracking());

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const NearestPoint after_nan = tracker.update(arc, Vec2(nan, 0));
  CHECK(after_nan.t == before.t);
  CHECK(after_nan.distance == before.distance);
  StrokeElement broken = arc;
  broken.control[1].x() = std::numeric_limits<double>::infinity();
  CHECK(tracker.update(broken, Vec2(0, 0)).t == before.t);
  CHECK(tracker.tracking());

  // A different element: after reset() the first update is global, not a descent from the old t.
  const StrokeElement line = StrokeElement::line(Vec2(0, 0), Vec2(0.1, 0));
  tracker.reset();
  CHECK_FALSE(tracker.tracking());
  CHECK(tracker.update(line, Vec2(0.07, 0.01)).t == Approx(0.7));
  const Vec2 points[4] = {Vec2(0, 0), Vec2(0.03, 0.03), Vec2(0, 0.03), Vec2(0.03, 0)};  // cusp
  const StrokeElement cusp = StrokeElement::bezier(points, 4);
  tracker.reset();
  const Vec2 near_end = cusp.end() + Vec2(0.001, 0);
  CHECK(tracker.update(cusp, near_end).t == Approx(calligraphy::nearest_point(cusp, near_end).t));
}

TEST_CASE("Tracker options out of range throw InvalidArgument", "[nearest_point][tracker]") {
  static_assert(noexcept(std::declval<NearestPointTracker&>().update(std::declval<const StrokeElement&>(),
                                                                     std::declval<const Vec2&>())));
  using calligraphy::InvalidArgument;
  NearestPointTrackerOptions options;
  options.global_check_period = 0;
  CHECK_THROWS_AS(NearestPointTracker(options), InvalidArgument);
  options = {};
  options.switch_hysteresis_m = -1e-3;
  CHECK_THROWS_WITH(NearestPointTracker(options), Catch::Matchers::Contains("switch_hysteresis_m"));
  options = {};
  options.newton_iterations = 0;
  CHECK_THROWS_AS(NearestPointTracker(options), InvalidArgument);
  options = {};
  options.tolerance = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(NearestPointTracker(options), InvalidArgument);
}
