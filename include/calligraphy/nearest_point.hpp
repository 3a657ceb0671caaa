#pragma once
/// \file nearest_point.hpp
/// Nearest point on a stroke element (paper section 4.3), with selectable methods so users can
/// trade speed for accuracy. All methods are allocation-free and never return NaN.

#include "calligraphy/element.hpp"

namespace calligraphy {

/// How the nearest point on a Bezier element is found.
enum class NearestPointMethod {
  /// Global: all roots of (B(t)-P).B'(t) (a degree 2n-1 polynomial in Bernstein form) isolated by
  /// de Casteljau subdivision, plus both endpoints. The default.
  exact,
  /// Newton iterations from `newton_starts` evenly spaced starts, `newton_iterations` each.
  newton,
  /// The paper's greedy subdivision (section 4.3.2), stopping when the distance difference < tolerance.
  subdivision,
};

/// Options of `nearest_point`. Lengths are in the element's units (m for a placed element).
struct NearestPointOptions {
  NearestPointMethod method = NearestPointMethod::exact;
  /// Tolerance of the parameter search: for `exact` the root isolation stops when the parameter
  /// interval is below this (dimensionless, in t); for `subdivision` it is the paper's e, a length.
  double tolerance = 1e-12;
  int newton_starts = 8;      ///< `newton` only
  int newton_iterations = 6;  ///< `newton` only
};

/// Result: parameter t in [0, 1], the foot point B(t), and the distance |P - B(t)|.
struct NearestPoint {
  double t = 0.0;
  Vec2 foot = Vec2::Zero();
  double distance = 0.0;
};

/// Nearest point on `element` to `p`. Throws InvalidArgument when `p` or a control point is not finite
/// or when the options are out of range (tolerance <= 0, starts or iterations < 1).
NearestPoint nearest_point(const StrokeElement& element, const Vec2& p, const NearestPointOptions& options = {});

/// Nearest point on the segment a-b (t clamped to [0, 1]; a zero-length segment gives t = 0).
/// No checks: the caller guarantees finite input. Used on the servo path.
NearestPoint nearest_point_on_segment(const Vec2& a, const Vec2& b, const Vec2& p) noexcept;

}  // namespace calligraphy
