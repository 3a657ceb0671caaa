#include "eval/lib2geom_nearest.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

#ifdef CALLIGRAPHY_WITH_LIB2GEOM
#include <2geom/bezier-curve.h>
#include <2geom/bezier.h>
#include <2geom/curve.h>
#include <2geom/d2.h>
#include <2geom/exception.h>
#include <2geom/point.h>

#include <array>
#include <vector>
#endif

namespace calligraphy::cli {

namespace {

void require_finite(const Vec2& v, const std::string& what) {
  if (!std::isfinite(v.x()) || !std::isfinite(v.y())) {
    throw InvalidArgument("lib2geom nearest point: " + what + " is not finite");
  }
}

void require_element(const StrokeElement& element) {
  if (element.degree < 1 || element.degree > kMaxElementDegree) {
    throw InvalidArgument("lib2geom nearest point: element degree " + std::to_string(element.degree) +
                          " is not 1.." + std::to_string(kMaxElementDegree));
  }
  for (int i = 0; i <= element.degree; ++i) {
    require_finite(element.control[static_cast<std::size_t>(i)], "control point " + std::to_string(i));
  }
}

}  // namespace

#ifdef CALLIGRAPHY_WITH_LIB2GEOM

// A Bezier curve of any order in lib2geom is D2<Bezier>, one Bernstein polynomial per axis, whose
// coefficients are the control points' coordinates: no change of basis, so nothing is rounded.
// BezierCurve::nearestTime, which Geom::nearest_time(Point, Curve) calls, roots the Bernstein
// product (B - P) . B' and compares the roots with both ends.
struct Lib2geomCurve::Curve {
  Geom::BezierCurve bezier;
};

namespace {

// |B(t) - P| from the control points taken relative to P, as lib2geom compares its candidates (it
// subtracts P from the curve first): the distance then carries no rounding of global coordinates, and
// the error measured is that of lib2geom's t. De Casteljau on at most five points, no allocation.
double distance_at(const Geom::BezierCurve& curve, const Geom::Point& p, double t) {
  std::array<Geom::Point, kMaxElementDegree + 1> relative;
  const unsigned order = curve.order();
  for (unsigned i = 0; i <= order; ++i) relative[i] = curve.controlPoint(i) - p;
  for (unsigned level = 1; level <= order; ++level) {
    for (unsigned i = 0; i + level <= order; ++i) relative[i] = (1.0 - t) * relative[i] + t * relative[i + 1];
  }
  return Geom::L2(relative[0]);
}

}  // namespace

bool lib2geom_built() { return true; }

Lib2geomCurve::Lib2geomCurve(const StrokeElement& element) {
  require_element(element);
  // Bernstein coefficients per axis are the control points' coordinates.
  std::vector<Geom::Coord> x;
  std::vector<Geom::Coord> y;
  for (int i = 0; i <= element.degree; ++i) {
    const Vec2& control = element.control[static_cast<std::size_t>(i)];
    x.push_back(control.x());
    y.push_back(control.y());
  }
  curve_ = std::make_unique<Curve>(
      Curve{Geom::BezierCurve(Geom::D2<Geom::Bezier>(Geom::Bezier(x), Geom::Bezier(y)))});
}

NearestPoint Lib2geomCurve::nearest(const Vec2& p) const {
  require_finite(p, "the query point");
  const Geom::Point query(p.x(), p.y());
  NearestPoint result;
  try {
    result.t = Geom::nearest_time(query, curve_->bezier);
  } catch (const Geom::Exception& e) {
    throw Error(std::string("lib2geom nearest point: Geom::nearest_time threw: ") + e.what());
  }
  const Geom::Point foot = curve_->bezier.pointAt(result.t);
  result.foot = Vec2(foot.x(), foot.y());
  result.distance = distance_at(curve_->bezier, query, result.t);
  return result;
}

#else

struct Lib2geomCurve::Curve {};

bool lib2geom_built() { return false; }

Lib2geomCurve::Lib2geomCurve(const StrokeElement& element) {
  require_element(element);
  throw Error(
      "lib2geom nearest point: this build has no lib2geom (install lib2geom-dev and configure again)");
}

NearestPoint Lib2geomCurve::nearest(const Vec2& p) const {
  require_finite(p, "the query point");
  throw Error("lib2geom nearest point: this build has no lib2geom");
}

#endif

Lib2geomCurve::~Lib2geomCurve() = default;
Lib2geomCurve::Lib2geomCurve(Lib2geomCurve&&) noexcept = default;
Lib2geomCurve& Lib2geomCurve::operator=(Lib2geomCurve&&) noexcept = default;

}  // namespace calligraphy::cli
