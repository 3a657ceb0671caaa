// lib2geom's Geom::nearest_time as a column of `calligraphy bench nearest`: the conversion keeps the
// element's curve and parameter, and a build without lib2geom says "not built" instead of measuring.
#include "eval/lib2geom_nearest.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "eval/nearest_point_measurement.hpp"
#include "eval/nearest_point_report.hpp"
#include "eval/nearest_point_scenarios.hpp"

using namespace calligraphy;
using calligraphy::cli::lib2geom_built;
using calligraphy::cli::Lib2geomCurve;
using Catch::Matchers::Contains;

TEST_CASE("Lib2geomCurve keeps the element's curve and parameter", "[lib2geom]") {
  std::mt19937_64 random(7);
  for (int degree = 1; degree <= kMaxElementDegree; ++degree) {
    // 50 mm curves with the pen within 5 mm: lib2geom's absolute tolerances do not matter there.
    const auto queries = cli::random_curve_queries(degree, 200, random, 0.05, Vec2(0.01, -0.02), 0.0, 0.005);
    for (const cli::NearestPointQuery& query : queries) {
      if (!lib2geom_built()) {
        CHECK_THROWS_AS(Lib2geomCurve(query.element), Error);
        continue;
      }
      const Lib2geomCurve curve(query.element);
      const NearestPoint answer = curve.nearest(query.point);
      const NearestPoint exact = nearest_point(query.element, query.point);
      CAPTURE(degree, answer.t, exact.t);
      REQUIRE(answer.t >= 0.0);
      REQUIRE(answer.t <= 1.0);
      // Same parametrisation: lib2geom's point at t is ours (coordinates about 0.05 m).
      CHECK((answer.foot - query.element.point(answer.t)).norm() <= 1e-15);
      CHECK(answer.distance == Approx((answer.foot - query.point).norm()).margin(1e-15));
      // The same curve: never nearer than the global minimum, and here it finds it.
      CHECK(answer.distance >= exact.distance - 1e-15);
      CHECK(answer.distance <= exact.distance + 1e-12);
    }
  }
}

// A build configured with lib2geom must load its module from beside the test program, as the installed
// program does from beside itself: otherwise the cases above would silently take the "not built" branch.
TEST_CASE("A build with lib2geom loads its module", "[lib2geom]") {
#ifdef CALLIGRAPHY_TEST_EXPECT_LIB2GEOM
  CAPTURE(cli::lib2geom_missing());
  CHECK(lib2geom_built());
  CHECK(cli::lib2geom_missing().empty());
#else
  CHECK_FALSE(lib2geom_built());
  CHECK_THAT(cli::lib2geom_missing(), Contains("no lib2geom"));
#endif
}

TEST_CASE("Lib2geomCurve rejects a bad element or query point", "[lib2geom]") {
  StrokeElement element = StrokeElement::line(Vec2(0.0, 0.0), Vec2(0.01, 0.0));
  element.degree = 5;
  CHECK_THROWS_WITH(Lib2geomCurve(element), Contains("degree 5"));
  element.degree = 1;
  element.control[1].x() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(Lib2geomCurve(element), Contains("control point 1"));
  if (lib2geom_built()) {
    const Lib2geomCurve curve(StrokeElement::line(Vec2(0.0, 0.0), Vec2(0.01, 0.0)));
    CHECK_THROWS_AS(curve.nearest(Vec2(std::numeric_limits<double>::infinity(), 0.0)), InvalidArgument);
  }
}

TEST_CASE("The nearest-point table shows an unbuilt lib2geom as \"not built\"", "[lib2geom]") {
  cli::NearestPointMeasurement measurement;
  cli::NearestPointRow exact;
  exact.method = "exact";
  exact.degree = 3;
  exact.scenario = "corpus";
  exact.queries = 10;
  exact.ns_median = 100.0;
  cli::NearestPointRow missing = exact;
  missing.method = cli::kLib2geomMethod;
  missing.built = false;
  measurement.rows = {exact, missing};
  const std::string markdown = cli::nearest_point_markdown(measurement, {}, "test");
  CHECK_THAT(markdown, Contains("| lib2geom | 3 | corpus | 10 | not built |"));
  CHECK_THAT(markdown, Contains("lib2geom: not built"));
  // JSON carries measured rows only.
  CHECK_THAT(cli::nearest_point_json(measurement), !Contains("lib2geom"));
}
