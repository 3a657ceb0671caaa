#pragma once
// lib2geom's nearest point (Geom::nearest_time, lib2geom 1.2, https://gitlab.com/inkscape/lib2geom) on
// our stroke elements, as a further column of `calligraphy bench nearest`. lib2geom is optional at
// configure time; it is called from a module loaded on first use (lib2geom_module/), so that its 30 shared
// libraries load only for this column. Without the module `lib2geom_built()` is false and `Lib2geomCurve`
// throws.
#include <memory>
#include <string>

#include "calligraphy/model/element.hpp"
#include "calligraphy/model/nearest_point.hpp"

namespace calligraphy::cli {

/// Whether this build has lib2geom's module and it loads (loaded by the first call).
bool lib2geom_built();

/// Why lib2geom is not available ("this build has no lib2geom ...", the loader's message); empty when it is.
std::string lib2geom_missing();

/// One stroke element converted once to a Geom::BezierCurve with the same control points in the same
/// coordinates (Bernstein form, so the curve and its parameter t in [0, 1] are the element's own),
/// queried with Geom::nearest_time. The conversion allocates; queries allocate inside lib2geom.
class Lib2geomCurve {
 public:
  /// Throws InvalidArgument when the degree is not 1..4 or a control point is not finite, Error when
  /// lib2geom is not available (lib2geom_missing()).
  explicit Lib2geomCurve(const StrokeElement& element);
  ~Lib2geomCurve();
  Lib2geomCurve(Lib2geomCurve&&) noexcept;
  Lib2geomCurve& operator=(Lib2geomCurve&&) noexcept;
  Lib2geomCurve(const Lib2geomCurve&) = delete;
  Lib2geomCurve& operator=(const Lib2geomCurve&) = delete;

  /// t = Geom::nearest_time(p, curve); foot = the curve's point at t (lib2geom's evaluation);
  /// distance = |B(t) - p| evaluated on the control points relative to p, as lib2geom compares its
  /// candidates (element units). Throws InvalidArgument for a non-finite `p`, Error when
  /// lib2geom throws. Not on a moved-from curve.
  [[nodiscard]] NearestPoint nearest(const Vec2& p) const;

 private:
  struct Curve;
  std::unique_ptr<Curve> curve_;
};

}  // namespace calligraphy::cli
