#pragma once
// The local frame of one nearest-point query. Subtracting the first control point and dividing by
// a power of two (exact in binary floating point) makes every query look like one on a curve of
// size about 1 near the origin: the result does not depend on the element's offset (1e2 m) or
// scale (1e-6 m), and distances are computed from the exact local differences, not from rounded
// global coordinates.
#include <array>

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/element.hpp"

namespace calligraphy::detail {

struct LocalCurve {
  int degree = 1;
  std::array<Vec2, kMaxElementDegree + 1> q{};  ///< control points in the local frame
  Vec2 p = Vec2::Zero();                        ///< query point in the local frame
  Vec2 origin = Vec2::Zero();                   ///< first control point (element units)
  double scale = 1.0;                           ///< element units per local unit, a power of two
};

/// Point, first and second derivative of a curve at one parameter.
struct CurveJet {
  Vec2 point = Vec2::Zero();
  Vec2 first = Vec2::Zero();
  Vec2 second = Vec2::Zero();
};

/// The local frame of `element` and `p`: every local coordinate has magnitude <= 1.
/// Needs finite input (not checked).
LocalCurve to_local(const StrokeElement& element, const Vec2& p) noexcept;

/// B(t) in the local frame (de Casteljau).
Vec2 local_point(const LocalCurve& curve, double t) noexcept;
/// B(t), B'(t) and B''(t) in the local frame, from one de Casteljau pass.
CurveJet local_jet(const LocalCurve& curve, double t) noexcept;
/// |B(t) - P|^2 in local units.
double local_squared_distance(const LocalCurve& curve, double t) noexcept;
/// The result for parameter t, mapped back to element units.
NearestPoint local_result(const LocalCurve& curve, double t) noexcept;
/// Closed-form projection on the chord q0-q1 (degree 1), in the local frame (paper section 4.3.1).
NearestPoint local_segment_nearest(const LocalCurve& curve) noexcept;

}  // namespace calligraphy::detail
