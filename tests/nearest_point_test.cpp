// Nearest point on a stroke element: every method on every extreme case (see extreme_cases below),
// against the independent high-precision reference of src/cli/nearest_point_reference.hpp.
#include "calligraphy/model/nearest_point.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "eval/nearest_point_reference.hpp"

using calligraphy::InvalidArgument;
using calligraphy::NearestPoint;
using calligraphy::NearestPointMethod;
using calligraphy::NearestPointOptions;
using calligraphy::StrokeElement;
using calligraphy::Vec2;

namespace {

constexpr double kMm = 1e-3;

struct Case {
  std::string name;
  StrokeElement element;
  Vec2 point;
};

StrokeElement make(const std::vector<Vec2>& points) {
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

std::vector<Vec2> mm(std::vector<Vec2> points) {
  for (Vec2& point : points) point *= kMm;
  return points;
}

// Degree elevation: the same curve with one more control point.
StrokeElement elevate(const StrokeElement& e) {
  std::vector<Vec2> points(static_cast<std::size_t>(e.degree) + 2);
  points.front() = e.start();
  points.back() = e.end();
  for (int i = 1; i <= e.degree; ++i) {
    const double a = static_cast<double>(i) / (e.degree + 1);
    points[static_cast<std::size_t>(i)] =
        a * e.control[static_cast<std::size_t>(i - 1)] + (1 - a) * e.control[static_cast<std::size_t>(i)];
  }
  return make(points);
}

StrokeElement transformed(const StrokeElement& e, double scale, const Vec2& offset) {
  StrokeElement result = e;
  for (Vec2& point : result.control) point = offset + scale * point;
  return result;
}

// The extreme cases (the point on the curve, at an endpoint, on an end tangent's extension, at a
// centre of curvature; cusps, loops, coincident control points, far offsets, tiny scales) plus random
// curves, for one degree.
std::vector<Case> extreme_cases(int degree) {
  std::mt19937_64 random(static_cast<std::uint64_t>(100 + degree));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto random_element = [&](double side) {
    std::vector<Vec2> points;
    for (int i = 0; i <= degree; ++i) points.emplace_back(side * unit(random), side * unit(random));
    return make(points);
  };
  auto around = [&](const Vec2& centre, double radius) {
    const double angle = 2 * std::numbers::pi * unit(random);
    return Vec2(centre + radius * unit(random) * Vec2(std::cos(angle), std::sin(angle)));
  };
  std::vector<Case> cases;
  for (int i = 0; i < 40; ++i) {
    const StrokeElement e = random_element(50 * kMm);
    cases.push_back({"random within 5 mm", e, around(e.point(unit(random)), 5 * kMm)});
    cases.push_back({"random 50 mm out", e, around(e.point(unit(random)), 50 * kMm)});
    cases.push_back({"on the curve", e, e.point(unit(random))});
    cases.push_back({"far (1 m)", e, e.point(0.5) + Vec2(0.6, -0.8)});
    const Vec2 beyond_end = e.end() + 3 * kMm * e.unit_tangent(1.0);
    cases.push_back({"end tangent extension", e, beyond_end});
    const StrokeElement tiny = transformed(e, 2e-5, Vec2::Zero());  // 1e-6 m box
    cases.push_back({"scale 1e-6 m", tiny, around(tiny.point(unit(random)), 1e-7)});
    const StrokeElement big = transformed(e, 2e3, Vec2::Zero());  // 1e2 m box
    cases.push_back({"scale 1e2 m", big, around(big.point(unit(random)), 10.0)});
    const StrokeElement moved = transformed(e, 1.0, Vec2(100.0, -100.0));
    cases.push_back({"offset 1e2 m", moved, around(moved.point(unit(random)), 5 * kMm)});
    const StrokeElement tiny_moved = transformed(tiny, 1.0, Vec2(100.0, 100.0));
    cases.push_back({"offset 1e2 m, scale 1e-6 m", tiny_moved, around(tiny_moved.point(unit(random)), 1e-7)});
    const Vec2 spot = 50 * kMm * Vec2(unit(random), unit(random));
    const StrokeElement dot = make(std::vector<Vec2>(static_cast<std::size_t>(degree) + 1, spot));
    cases.push_back({"zero length", dot, around(spot, 5 * kMm)});
    cases.push_back({"zero length, P on it", dot, spot});
  }
  const StrokeElement e = random_element(50 * kMm);
  cases.push_back({"at the start", e, e.start()});
  cases.push_back({"at the end", e, e.end()});
  cases.push_back({"far (100 m)", e, Vec2(-60.0, 80.0)});
  if (degree >= 2) {
    StrokeElement cusp =
        degree == 2 ? make(mm({{0, 0}, {30, 30}, {0, 0}})) : make(mm({{0, 0}, {30, 30}, {0, 30}, {30, 0}}));
    if (degree == 4) cusp = elevate(cusp);
    cases.push_back({"at the cusp", cusp, cusp.point(0.5)});
    for (int i = 0; i < 40; ++i) cases.push_back({"near the cusp", cusp, around(cusp.point(0.5), 5 * kMm)});
    for (int i = 0; i < 10; ++i) {
      StrokeElement coincident = random_element(50 * kMm);
      coincident.control[1] = coincident.control[0];
      if (degree >= 3) coincident.control[static_cast<std::size_t>(degree - 1)] = coincident.end();
      cases.push_back(
          {"coincident control points", coincident, around(coincident.point(unit(random)), 5 * kMm)});
    }
    // Centre of curvature of the apex of a symmetric parabola: radius 10 mm, centre (0, 10) mm.
    StrokeElement arc = make(mm({{-20, 0}, {0, 40}, {20, 0}}));
    while (arc.degree < degree) arc = elevate(arc);
    cases.push_back({"centre of curvature", arc, Vec2(0, 10 * kMm)});
    cases.push_back({"beyond the centre of curvature (two equal minima)", arc, Vec2(0, 5 * kMm)});
  }
  if (degree >= 3) {
    StrokeElement loop = make(mm({{0, 0}, {45, 30}, {-15, 30}, {30, 0}}));
    if (degree == 4) loop = elevate(loop);
    for (int i = 0; i < 40; ++i) cases.push_back({"loop", loop, around(loop.point(0.5), 8 * kMm)});
  }
  return cases;
}

NearestPointOptions with_method(NearestPointMethod method) {
  NearestPointOptions options;
  options.method = method;
  return options;
}

void check_well_formed(const Case& c, const NearestPoint& result) {
  INFO(c.name);
  REQUIRE(std::isfinite(result.t));
  REQUIRE(result.foot.allFinite());
  REQUIRE(std::isfinite(result.distance));
  CHECK(result.t >= 0.0);
  CHECK(result.t <= 1.0);
  CHECK(result.distance >= 0.0);
}

}  // namespace

TEST_CASE("Segment projection: interior, clamped ends and a zero-length segment", "[nearest_point]") {
  static_assert(noexcept(calligraphy::nearest_point_on_segment(
      std::declval<const Vec2&>(), std::declval<const Vec2&>(), std::declval<const Vec2&>())));
  const Vec2 a(1.0, 1.0);
  const Vec2 b(5.0, 1.0);
  NearestPoint r = calligraphy::nearest_point_on_segment(a, b, Vec2(2.0, 4.0));
  CHECK(r.t == Approx(0.25));
  CHECK(r.distance == Approx(3.0));
  CHECK((r.foot - Vec2(2.0, 1.0)).norm() < 1e-15);
  r = calligraphy::nearest_point_on_segment(a, b, Vec2(-3.0, 4.0));
  CHECK(r.t == 0.0);
  CHECK(r.distance == Approx(5.0));
  r = calligraphy::nearest_point_on_segment(a, b, Vec2(9.0, -2.0));
  CHECK(r.t == 1.0);
  CHECK(r.distance == Approx(5.0));
  r = calligraphy::nearest_point_on_segment(a, a, Vec2(4.0, 5.0));
  CHECK(r.t == 0.0);
  CHECK(r.foot == a);
  CHECK(r.distance == Approx(5.0));
}

TEST_CASE("exact finds the global minimum to 1e-12 of (polygon length + distance) on every extreme case",
          "[nearest_point]") {
  for (int degree = 1; degree <= calligraphy::kMaxElementDegree; ++degree) {
    for (const Case& c : extreme_cases(degree)) {
      const NearestPoint result = calligraphy::nearest_point(c.element, c.point);
      check_well_formed(c, result);
      const auto reference = calligraphy::cli::reference_nearest_point(c.element, c.point);
      const double error = std::abs(static_cast<double>(result.distance - reference.distance));
      const double bound = 1e-12 * (c.element.polygon_length() + static_cast<double>(reference.distance));
      INFO(c.name << ", degree " << degree << ": distance " << result.distance << " at t " << result.t
                  << ", reference " << static_cast<double>(reference.distance) << " at t "
                  << static_cast<double>(reference.t));
      CHECK(error <= bound);
      // The foot is B(t) and lies at the reported distance (within the rounding of its coordinates).
      const double coordinate_rounding = 4e-16 * (c.point.norm() + c.element.start().norm());
      CHECK((result.foot - c.element.point(result.t)).norm() <=
            1e-12 * c.element.polygon_length() + coordinate_rounding);
      CHECK(std::abs((c.point - result.foot).norm() - result.distance) <=
            1e-12 * (c.element.polygon_length() + result.distance) + coordinate_rounding);
    }
  }
}

TEST_CASE("The cusp cubic: a point at the cusp is at t = 0.5, distance 0", "[nearest_point]") {
  const auto points = mm({{0, 0}, {30, 30}, {0, 30}, {30, 0}});
  const StrokeElement cusp = make(points);
  const NearestPoint result = calligraphy::nearest_point(cusp, cusp.point(0.5));
  CHECK(result.t == Approx(0.5).margin(1e-6));
  CHECK(result.distance < 1e-15);
}

TEST_CASE("Equal minima: the smallest t is returned", "[nearest_point]") {
  // P beyond the apex's centre of curvature of a symmetric parabola: minima at t = 0.25 and 0.75.
  const StrokeElement arc = make(mm({{-20, 0}, {0, 40}, {20, 0}}));
  const NearestPoint result = calligraphy::nearest_point(arc, Vec2(0, 5 * kMm));
  CHECK(result.t == Approx(0.25).margin(1e-9));
  CHECK(result.distance == Approx(std::sqrt(200.0) * kMm).epsilon(1e-12));
}

TEST_CASE("newton: never NaN, never below the true minimum, exact where a start lies in the basin",
          "[nearest_point]") {
  for (int degree = 1; degree <= calligraphy::kMaxElementDegree; ++degree) {
    int failures = 0;
    int total = 0;
    for (const Case& c : extreme_cases(degree)) {
      const NearestPoint result =
          calligraphy::nearest_point(c.element, c.point, with_method(NearestPointMethod::newton));
      check_well_formed(c, result);
      const auto reference = calligraphy::cli::reference_nearest_point(c.element, c.point);
      const double length = c.element.polygon_length();
      const double rounding = 1e-12 * (length + static_cast<double>(reference.distance));
      INFO(c.name << ", degree " << degree);
      // A candidate is a point of the curve: its distance cannot be below the minimum.
      CHECK(result.distance >= static_cast<double>(reference.distance) - rounding);
      ++total;
      if (result.distance - static_cast<double>(reference.distance) > 1e-4) ++failures;
    }
    // Documented: no global guarantee; measured failure rates are in docs/nearest-point.md. With
    // 8 starts x 6 iterations it must still succeed on the large majority of these cases.
    INFO("degree " << degree << ": " << failures << " of " << total << " off by > 0.1 mm");
    CHECK(failures * 20 < total);
  }
  // A line is solved in closed form by every method.
  const StrokeElement line = StrokeElement::line(Vec2(0, 0), Vec2(1, 0));
  CHECK(calligraphy::nearest_point(line, Vec2(0.3, 2), with_method(NearestPointMethod::newton)).t ==
        Approx(0.3));
}

TEST_CASE("newton with one start can miss the global minimum (documented)", "[nearest_point]") {
  // Two equal-ish minima at t = 0.25 and 0.75 plus a maximum at 0.5; shift P towards the right one.
  const StrokeElement arc = make(mm({{-20, 0}, {0, 40}, {20, 0}}));
  const Vec2 p(2 * kMm, 5 * kMm);
  NearestPointOptions options = with_method(NearestPointMethod::newton);
  options.newton_starts = 1;  // starts at t = 0.5, a maximum where f' < 0: Newton stops there
  options.newton_iterations = 1;
  const NearestPoint newton = calligraphy::nearest_point(arc, p, options);
  const NearestPoint exact = calligraphy::nearest_point(arc, p);
  CHECK(newton.distance > exact.distance + 1e-3);
}

TEST_CASE("subdivision (paper section 4.3.2): well formed, converges on a simple arc, fails where documented",
          "[nearest_point]") {
  for (int degree = 1; degree <= calligraphy::kMaxElementDegree; ++degree) {
    for (const Case& c : extreme_cases(degree)) {
      NearestPointOptions options = with_method(NearestPointMethod::subdivision);
      options.tolerance = 1e-9;
      check_well_formed(c, calligraphy::nearest_point(c.element, c.point, options));
    }
  }
  const StrokeElement arc = make(mm({{-20, 0}, {0, 40}, {20, 0}}));
  NearestPointOptions options = with_method(NearestPointMethod::subdivision);
  options.tolerance = 1e-12;
  // Convex side, one minimum near t = 0.3: the greedy descent keeps the right half every time.
  const Vec2 outside = arc.point(0.3) + 5 * kMm * Vec2(-0.8, 0.6).normalized();
  const NearestPoint converged = calligraphy::nearest_point(arc, outside, options);
  const NearestPoint exact = calligraphy::nearest_point(arc, outside);
  CHECK(std::abs(converged.distance - exact.distance) < 1e-9);
  CHECK(converged.t == Approx(exact.t).margin(1e-6));
  // Documented failure: P on the symmetry axis outside the apex. The two child midpoints B(0.25)
  // and B(0.75) are equally far, so the paper's rule stops at once and returns the middle of their
  // chord, 10 mm below the curve.
  const Vec2 above(0, 30 * kMm);
  const NearestPoint stopped = calligraphy::nearest_point(arc, above, options);
  CHECK(stopped.t == 0.5);
  CHECK((stopped.foot - Vec2(0, 15 * kMm)).norm() < 1e-12);
  CHECK(stopped.distance - calligraphy::nearest_point(arc, above).distance > 1e-3);
}

TEST_CASE("No NaN leaves a query, whatever the method and options", "[nearest_point]") {
  for (int degree = 1; degree <= calligraphy::kMaxElementDegree; ++degree) {
    for (const Case& c : extreme_cases(degree)) {
      for (const NearestPointMethod method :
           {NearestPointMethod::exact, NearestPointMethod::newton, NearestPointMethod::subdivision}) {
        for (const double tolerance : {1e-300, 1e-12, 0.5, 1e3}) {
          NearestPointOptions options = with_method(method);
          options.tolerance = tolerance;
          options.newton_starts = 1;
          options.newton_iterations = 1;
          check_well_formed(c, calligraphy::nearest_point(c.element, c.point, options));
        }
      }
    }
  }
  // Coordinates up to the documented limit.
  const StrokeElement huge = make({{-1e150, 0}, {0, 1e150}, {1e150, 0}});
  check_well_formed({"huge", huge, Vec2(0, -1e150)}, calligraphy::nearest_point(huge, Vec2(0, -1e150)));
  const StrokeElement denormal = make({{0, 0}, {4e-320, 0}, {0, 4e-320}});
  check_well_formed({"subnormal", denormal, Vec2(1, 1)}, calligraphy::nearest_point(denormal, Vec2(1, 1)));
  // The element and the query all subnormal: the local frame's scale 2^-exponent would overflow.
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const StrokeElement& element :
       {make({{tiny, 0}, {0, tiny}}), make({{tiny, 0}, {0, tiny}, {4e-320, 4e-320}})}) {
    for (const NearestPointMethod method :
         {NearestPointMethod::exact, NearestPointMethod::newton, NearestPointMethod::subdivision}) {
      const auto found = calligraphy::nearest_point(element, Vec2(0, 0), with_method(method));
      check_well_formed({"all subnormal", element, Vec2(0, 0)}, found);
      // exact: no farther than the start, up to the subnormal grid's rounding (hypot: the squared norm of a
      // subnormal vector underflows to 0). Subdivision stops at its absolute tolerance, far above this
      // element.
      if (method == NearestPointMethod::exact)
        CHECK(found.distance <= std::hypot(element.control[0].x(), element.control[0].y()) + 4 * tiny);
    }
  }
}

TEST_CASE("NaN, infinite or out-of-range input is rejected with InvalidArgument naming it",
          "[nearest_point]") {
  using Catch::Matchers::Contains;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const StrokeElement e = make(mm({{0, 0}, {10, 20}, {30, 0}}));
  CHECK_THROWS_WITH(calligraphy::nearest_point(e, Vec2(nan, 0)),
                    Contains("query point p") && Contains("nan"));
  CHECK_THROWS_AS(calligraphy::nearest_point(e, Vec2(0, inf)), InvalidArgument);
  CHECK_THROWS_AS(calligraphy::nearest_point(e, Vec2(0, 1e151)), InvalidArgument);
  StrokeElement bad = e;
  bad.control[2] = Vec2(-inf, 0);
  CHECK_THROWS_WITH(calligraphy::nearest_point(bad, Vec2(0, 0)),
                    Contains("control point 2") && Contains("inf"));
  bad = e;
  bad.degree = 5;
  CHECK_THROWS_WITH(calligraphy::nearest_point(bad, Vec2(0, 0)), Contains("degree 5"));
  bad.degree = 0;
  CHECK_THROWS_AS(calligraphy::nearest_point(bad, Vec2(0, 0)), InvalidArgument);
  for (const double tolerance : {0.0, -1.0, nan, inf}) {
    NearestPointOptions options;
    options.tolerance = tolerance;
    CHECK_THROWS_WITH(calligraphy::nearest_point(e, Vec2(0, 0), options), Contains("options.tolerance"));
  }
  NearestPointOptions options;
  options.newton_starts = 0;
  CHECK_THROWS_WITH(calligraphy::nearest_point(e, Vec2(0, 0), options),
                    Contains("options.newton_starts = 0"));
  options = {};
  options.newton_iterations = -3;
  CHECK_THROWS_WITH(calligraphy::nearest_point(e, Vec2(0, 0), options),
                    Contains("options.newton_iterations = -3"));
  // The control points of a line beyond its degree are not read.
  StrokeElement line = StrokeElement::line(Vec2(0, 0), Vec2(1, 0));
  line.control[3] = Vec2(nan, nan);
  CHECK_NOTHROW(calligraphy::nearest_point(line, Vec2(0.5, 1)));
}
