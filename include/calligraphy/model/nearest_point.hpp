#pragma once
/// \file nearest_point.hpp
/// Nearest point on a stroke element (paper section 4.3), with selectable methods so users can
/// trade speed for accuracy. All methods are allocation-free and never return NaN.
///
/// Every method works in a local frame (origin at the first control point, lengths scaled by a
/// power of two), so the result does not degrade with the distance of the element from the origin
/// (1e2 m offsets) or with its size (1e-6 m elements). Degree-1 elements (LSE) use the closed-form
/// projection of `nearest_point_on_segment` with every method, as the paper does (section 4.3.1).
/// Measured accuracy and speed of every method: docs/nearest-point.md.

#include <array>
#include <span>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// How the nearest point on a Bezier element is found.
enum class NearestPointMethod {
  /// Global: all roots of f(t) = (B(t)-P).B'(t) (a degree 2n-1 polynomial in Bernstein form)
  /// isolated by de Casteljau subdivision and the sign changes of the coefficients, refined by
  /// safeguarded Newton/bisection, plus both endpoints (Schneider, Graphics Gems 1990).
  /// Guarantee: the global minimum is found; the parameter of an interior minimum is within
  /// `tolerance` (in t) of a root of f, so the distance error (m) is of the order of machine
  /// epsilon times (polygon length + distance), far below 1e-12 x polygon length for tolerance
  /// 1e-12. The default.
  exact,
  /// Newton iterations on f from `newton_starts` evenly spaced starts t = (i + 1/2) / starts,
  /// `newton_iterations` each, clamped to [0, 1]; an iteration stops where f'(t) <= 0 (P beyond the
  /// centre of curvature). Both endpoints are candidates. Guarantee: only a local one (a minimum
  /// near a start is converged quadratically); a start can miss the global minimum or stop short,
  /// so the error is unbounded in general (rate measured in docs/nearest-point.md).
  newton,
  /// The paper's greedy subdivision (section 4.3.2), stopping when the distance difference <
  /// tolerance (a length, m). Guarantee: none; it can keep the wrong half (errors of several mm
  /// on 50 mm curves, measured in docs/nearest-point.md). Kept to reproduce the paper.
  subdivision,
};

/// The one spelling of each method (records, Python).
template <>
struct EnumTable<NearestPointMethod> {
  static constexpr std::string_view name = "NearestPointMethod";
  static constexpr std::array<EnumEntry<NearestPointMethod>, 3> entries{{
      {NearestPointMethod::exact, "exact", "Bernstein root isolation (Schneider 1990): the global minimum"},
      {NearestPointMethod::newton, "newton", "Newton's method from several starts"},
      {NearestPointMethod::subdivision, "subdivision", "the paper's greedy subdivision (section 4.3)"},
  }};
};

/// The coarsest `NearestPointOptions::tolerance` a force law (and a trial record) takes: 1e-3, a thousandth
/// of the parameter range for `exact` (in t) and 1 mm for `subdivision` (the paper's e, in m), coarser than
/// any search is meant to stop (the default is 1e-12; docs/nearest-point.md). `nearest_point` itself takes
/// any finite tolerance > 0.
inline constexpr double kMaxForceLawNearestTolerance = 1e-3;
/// That tolerance's range, (0, kMaxForceLawNearestTolerance]: ForceLawParameters::validate checks it and a
/// trial record's schema states it.
inline constexpr ParameterRange kForceLawNearestToleranceRange{
    .low = 0.0, .high = kMaxForceLawNearestTolerance, .low_open = true};

/// Options of `nearest_point`. Lengths are in the element's units (m for a placed element).
struct NearestPointOptions {
  NearestPointMethod method = NearestPointMethod::exact;
  /// Tolerance of the parameter search: for `exact` the root isolation stops when the parameter
  /// interval is below this (dimensionless, in t); for `subdivision` it is the paper's e, a length
  /// (element units, m). Must be finite and > 0.
  double tolerance = 1e-12;
  int newton_starts = 8;      ///< `newton` only: number of starts, >= 1
  int newton_iterations = 6;  ///< `newton` only: iterations per start, >= 1
};

/// Result: parameter t in [0, 1] (dimensionless), the foot point B(t) and the distance |P - B(t)|,
/// both in the element's units (m for a placed element). The distance is computed in the local
/// frame, so it is accurate even where the foot's coordinates are rounded (large offsets).
/// Exception: `subdivision` returns, as the paper does, the midpoint of the chord between the last
/// two child midpoints as foot (off the curve by at most that chord's sagitta) and t is the
/// parameter midway between them.
struct NearestPoint {
  double t = 0.0;
  Vec2 foot = Vec2::Zero();
  double distance = 0.0;
};

/// Largest |x| or |y| of a point or control point `nearest_point` accepts: squared distances stay finite.
inline constexpr double kMaxNearestPointCoordinate = 1e150;

/// Nearest point on `element` to `p` (element units, m for a placed element).
/// Throws InvalidArgument when `p` or a control point is not finite or has a magnitude above 1e150
/// (kMaxNearestPointCoordinate; squared distances would overflow), when the element's degree is not 1..4, or
/// when the options are out of range (tolerance not finite or <= 0, starts or iterations < 1). Among equally
/// near points the one with the smallest t is returned. Allocation-free.
NearestPoint nearest_point(const StrokeElement& element, const Vec2& p,
                           const NearestPointOptions& options = {});

/// Distance from `p` to the nearest of `elements` (element units, m for placed elements; infinity for
/// none): the least `nearest_point(e, p).distance`, exact, skipping each element whose control points'
/// bounding box is already no nearer (a Bezier curve lies in the convex hull of its control points).
/// Throws as `nearest_point`.
double distance_to_elements(std::span<const StrokeElement> elements, const Vec2& p);

/// Nearest point on the segment a-b (t clamped to [0, 1]; a zero-length segment gives t = 0).
/// Lengths in the caller's units (m). No checks: the caller guarantees finite input. Used on the
/// servo path.
NearestPoint nearest_point_on_segment(const Vec2& a, const Vec2& b, const Vec2& p) noexcept;

}  // namespace calligraphy
