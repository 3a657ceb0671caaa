#pragma once
/// \file element.hpp
/// Stroke elements (paper section 3.2): the line segment stroke element (LSE) and the curve
/// segment stroke element (CSE), a Bezier curve in Bernstein form (paper eq. 1). The paper prints
/// a degree-4 sum although its text says "third order"; degrees 1 to 4 are supported here, an LSE is
/// degree 1. Value type, fixed capacity, never allocates. Coordinates are in whatever units the
/// control points use (model units in a `Character`, metres once placed in a `Scene`).

#include <array>
#include <cstdint>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// Kind of stroke element (paper section 3.2).
enum class ElementKind : std::uint8_t {
  line,    ///< LSE: straight segment between two control points
  bezier,  ///< CSE: Bezier curve of degree 2 to 4
};

/// Highest supported Bezier degree (5 control points, the paper's eq. 1).
inline constexpr int kMaxElementDegree = 4;

/// One stroke element: a Bezier curve of degree 1 (LSE) to 4 (CSE) with `degree + 1` control points.
struct StrokeElement {
  ElementKind kind = ElementKind::line;
  int degree = 1;  ///< 1 for an LSE, 2..4 for a CSE
  /// First degree+1 entries used; the rest stay zero (Eigen does not zero-initialise by itself).
  std::array<Vec2, kMaxElementDegree + 1> control{Vec2::Zero(), Vec2::Zero(), Vec2::Zero(), Vec2::Zero(),
                                                  Vec2::Zero()};

  /// An LSE from `a` to `b` (equal points give a zero-length LSE, paper section 4.3.1 rule (d)).
  /// Throws InvalidArgument "StrokeElement::line: control point <i> is not finite" for a NaN or
  /// infinite coordinate.
  static StrokeElement line(const Vec2& a, const Vec2& b);
  /// A CSE from 3 to 5 control points (degree 2 to 4). Throws InvalidArgument for another count, or
  /// "StrokeElement::bezier: control point <i> is not finite" for a NaN or infinite coordinate.
  static StrokeElement bezier(const Vec2* points, int count);

  [[nodiscard]] int point_count() const { return degree + 1; }
  [[nodiscard]] const Vec2& start() const { return control[0]; }
  [[nodiscard]] const Vec2& end() const { return control[static_cast<std::size_t>(degree)]; }

  /// Point at parameter t in [0, 1] (de Casteljau, numerically stable).
  [[nodiscard]] Vec2 point(double t) const;
  /// First derivative dB/dt at t.
  [[nodiscard]] Vec2 derivative(double t) const;
  /// Unit tangent at t; falls back to the chord, then to +x, where the derivative vanishes.
  [[nodiscard]] Vec2 unit_tangent(double t) const;
  /// Length of the control polygon (an upper bound of the arc length).
  [[nodiscard]] double polygon_length() const;
  /// Arc length by adaptive Gauss-Legendre quadrature to a relative tolerance of about 1e-9.
  [[nodiscard]] double arc_length() const;
};

/// Eq. (6): the feature point at the end of `element` has been written (phi > 0) when
/// V_t . V_f > margin, V_t the element's unit tangent at its end and V_f the vector from that point to
/// the tip. `margin_m` >= 0 [m] is a hysteresis band (section 6): 0 is the paper's rule.
[[nodiscard]] bool feature_plane_passed(const StrokeElement& element, const Vec2& tip,
                                        double margin_m = 0.0) noexcept;

}  // namespace calligraphy
