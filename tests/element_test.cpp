#include "calligraphy/model/element.hpp"

#include <catch2/catch.hpp>

#include "calligraphy/core/errors.hpp"

using calligraphy::StrokeElement;
using calligraphy::Vec2;

TEST_CASE("A quartic CSE evaluates eq. (1) and its derivative", "[element]") {
  const Vec2 pts[5] = {{0, 0}, {1, 2}, {3, 3}, {4, 1}, {5, 0}};
  const auto e = StrokeElement::bezier(pts, 5);
  REQUIRE(e.degree == 4);
  // Eq. (1) at u = 0.3 by direct Bernstein sum.
  const double u = 0.3;
  const double b[5] = {std::pow(1 - u, 4), 4 * u * std::pow(1 - u, 3), 6 * u * u * std::pow(1 - u, 2),
                       4 * std::pow(u, 3) * (1 - u), std::pow(u, 4)};
  Vec2 expected = Vec2::Zero();
  for (int i = 0; i < 5; ++i) expected += b[i] * pts[i];
  CHECK((e.point(u) - expected).norm() < 1e-12);
  const double h = 1e-6;
  const Vec2 numeric = (e.point(u + h) - e.point(u - h)) / (2 * h);
  CHECK((e.derivative(u) - numeric).norm() < 1e-6);
  CHECK(e.point(0.0) == pts[0]);
  CHECK((e.point(1.0) - pts[4]).norm() < 1e-15);
}

TEST_CASE("Arc length of a straight cubic equals the chord", "[element]") {
  const Vec2 pts[4] = {{0, 0}, {1, 0}, {2, 0}, {3, 0}};
  CHECK(StrokeElement::bezier(pts, 4).arc_length() == Approx(3.0).epsilon(1e-9));
  CHECK(StrokeElement::line({0, 0}, {3, 4}).arc_length() == Approx(5.0));
}

TEST_CASE("A CSE needs 3 to 5 control points", "[element]") {
  const Vec2 pts[6] = {};
  CHECK_THROWS_AS(StrokeElement::bezier(pts, 2), calligraphy::InvalidArgument);
  CHECK_THROWS_AS(StrokeElement::bezier(pts, 6), calligraphy::InvalidArgument);
}

TEST_CASE("Unit tangent survives a cusp and a point element", "[element]") {
  const Vec2 cusp[4] = {{0, 0}, {30, 30}, {0, 30}, {30, 0}};
  const auto e = StrokeElement::bezier(cusp, 4);
  CHECK(e.unit_tangent(0.5).allFinite());
  CHECK(std::abs(e.unit_tangent(0.5).norm() - 1.0) < 1e-12);
  const auto dot = StrokeElement::line({1, 1}, {1, 1});
  CHECK(dot.unit_tangent(0.0) == Vec2::UnitX());
}
