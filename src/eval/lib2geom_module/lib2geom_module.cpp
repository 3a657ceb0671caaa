// lib2geom's nearest point on a Bezier curve (Geom::nearest_time, lib2geom 1.2,
// https://gitlab.com/inkscape/lib2geom), built as a module of its own (lib2geom_module.hpp says why).
#include "lib2geom_module.hpp"

#include <2geom/bezier-curve.h>
#include <2geom/bezier.h>
#include <2geom/curve.h>
#include <2geom/d2.h>
#include <2geom/exception.h>
#include <2geom/point.h>

#include <array>
#include <cstdio>
#include <exception>
#include <vector>

namespace {

constexpr int kMaxControlPoints = 5;

void put_error(char* error, std::size_t error_size, const char* what) {
  if (error != nullptr && error_size > 0) std::snprintf(error, error_size, "%s", what);
}

// |B(t) - P| from the control points taken relative to P, as lib2geom compares its candidates (it
// subtracts P from the curve first): the distance then carries no rounding of global coordinates, and
// the error measured is that of lib2geom's t. De Casteljau on at most five points, no allocation.
double distance_at(const Geom::BezierCurve& curve, const Geom::Point& p, double t) {
  std::array<Geom::Point, kMaxControlPoints> relative;
  const unsigned order = curve.order();
  for (unsigned i = 0; i <= order; ++i) relative[i] = curve.controlPoint(i) - p;
  for (unsigned level = 1; level <= order; ++level) {
    for (unsigned i = 0; i + level <= order; ++i) relative[i] = (1.0 - t) * relative[i] + t * relative[i + 1];
  }
  return Geom::L2(relative[0]);
}

}  // namespace

extern "C" {

// A Bezier curve of any order in lib2geom is D2<Bezier>, one Bernstein polynomial per axis, whose
// coefficients are the control points' coordinates: no change of basis, so nothing is rounded.
__attribute__((visibility("default"))) void* calligraphy_lib2geom_curve_new(const double* x, const double* y,
                                                                            int points, char* error,
                                                                            std::size_t error_size) {
  if (points < 2 || points > kMaxControlPoints) {
    put_error(error, error_size, "control points are not 2..5");
    return nullptr;
  }
  try {
    const std::vector<Geom::Coord> xs(x, x + points);
    const std::vector<Geom::Coord> ys(y, y + points);
    return new Geom::BezierCurve(Geom::D2<Geom::Bezier>(Geom::Bezier(xs), Geom::Bezier(ys)));
  } catch (const std::exception& e) {
    put_error(error, error_size, e.what());
    return nullptr;
  }
}

__attribute__((visibility("default"))) void calligraphy_lib2geom_curve_delete(void* curve) {
  delete static_cast<Geom::BezierCurve*>(curve);
}

// BezierCurve::nearestTime, which Geom::nearest_time(Point, Curve) calls, roots the Bernstein product
// (B - P) . B' and compares the roots with both ends.
__attribute__((visibility("default"))) int calligraphy_lib2geom_nearest(const void* curve, double px,
                                                                        double py, double* out, char* error,
                                                                        std::size_t error_size) {
  const auto& bezier = *static_cast<const Geom::BezierCurve*>(curve);
  const Geom::Point query(px, py);
  try {
    const double t = Geom::nearest_time(query, bezier);
    const Geom::Point foot = bezier.pointAt(t);
    out[0] = t;
    out[1] = foot.x();
    out[2] = foot.y();
    out[3] = distance_at(bezier, query, t);
    return 0;
  } catch (const std::exception& e) {
    put_error(error, error_size, e.what());
    return 1;
  }
}
}
