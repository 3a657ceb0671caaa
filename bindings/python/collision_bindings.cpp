// collision: the nearest point on a stroke element (include/calligraphy/collision/nearest_point.hpp,
// paper section 4.3) and its options.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.hpp"
#include "calligraphy/collision/nearest_point.hpp"
#include "calligraphy/collision/stroke_progress.hpp"
#include "calligraphy/core/errors.hpp"
#include "model_bindings.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {
namespace {

// Newton starts and iterations cost linearly; beyond this a call from Python is a mistake, not a need.
constexpr int kMaxNewtonCount = 1000;

void check_options(const NearestPointOptions& o, const std::string& prefix) {
  if (!(o.tolerance > 0.0) || !std::isfinite(o.tolerance)) {
    throw InvalidArgument(prefix + "tolerance = " + std::to_string(o.tolerance) + " must be finite and > 0");
  }
  if (o.newton_starts < 1 || o.newton_starts > kMaxNewtonCount) {
    throw InvalidArgument(prefix + "newton_starts = " + std::to_string(o.newton_starts) + " must be in 1.." +
                          std::to_string(kMaxNewtonCount));
  }
  if (o.newton_iterations < 1 || o.newton_iterations > kMaxNewtonCount) {
    throw InvalidArgument(prefix + "newton_iterations = " + std::to_string(o.newton_iterations) +
                          " must be in 1.." + std::to_string(kMaxNewtonCount));
  }
}

StrokeElement element_from(py::handle object) {
  if (py::isinstance<StrokeElement>(object)) return object.cast<StrokeElement>();
  return element_from_points(object, "element");
}

py::tuple nearest_point_py(const ElementLike& element_object, const ArrayLike& point,
                           const Checked<NearestPointMethod>& method, const Checked<double>& tolerance,
                           const Checked<int>& newton_starts, const Checked<int>& newton_iterations) {
  const StrokeElement element = element_from(element_object.object);
  NearestPointOptions options;
  options.method = take(method, "method");
  options.tolerance = take(tolerance, "tolerance");
  options.newton_starts = take(newton_starts, "newton_starts");
  options.newton_iterations = take(newton_iterations, "newton_iterations");
  check_options(options, "");
  const Vectors p = as_vectors(point.object, 2, "point");
  if (p.single) {
    const NearestPoint r = nearest_point(element, p.vec2(0), options);
    return py::make_tuple(r.t, to_array(r.foot), r.distance);
  }
  auto t = new_array({p.count});
  auto foot = new_array({p.count, 2});
  auto distance = new_array({p.count});
  {
    auto tw = t.mutable_unchecked<1>();
    auto fw = foot.mutable_unchecked<2>();
    auto dw = distance.mutable_unchecked<1>();
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < p.count; ++i) {
      const NearestPoint r = nearest_point(element, p.vec2(i), options);
      tw(i) = r.t;
      fw(i, 0) = r.foot.x();
      fw(i, 1) = r.foot.y();
      dw(i) = r.distance;
    }
  }
  return py::make_tuple(t, foot, distance);
}

}  // namespace

void bind_collision(py::module_& m) {
  py::enum_<NearestPointMethod>(m, "NearestPointMethod",
                                "How the nearest point on a Bezier element is found.")
      .value("exact", NearestPointMethod::exact,
             "global: every root of (B(t) - P).B'(t) isolated by subdivision (Schneider, Graphics Gems "
             "1990); the default")
      .value("newton", NearestPointMethod::newton, "Newton iterations from evenly spaced starts; local only")
      .value("subdivision", NearestPointMethod::subdivision,
             "the paper's greedy subdivision (section 4.3.2); no guarantee, kept to reproduce the paper");

  ParameterClass<NearestPointOptions>(
      m, "NearestPointOptions",
      "Options of nearest_point and of the renderer's foot-point search. "
      "Lengths are in the element's units (m for a placed element).",
      [](const NearestPointOptions& o) { check_options(o, "NearestPointOptions."); })
      .field("method", &NearestPointOptions::method, "a NearestPointMethod (or its name)")
      .field("tolerance", &NearestPointOptions::tolerance,
             "'exact': parameter interval (dimensionless, in t); 'subdivision': the paper's e, a length "
             "(element units). Finite, > 0")
      .field("newton_starts", &NearestPointOptions::newton_starts, "'newton' only: starts, 1..1000")
      .field("newton_iterations", &NearestPointOptions::newton_iterations,
             "'newton' only: iterations per start, 1..1000")
      .finish();

  ParameterClass<StrokeAcceptance>(
      m, "StrokeAcceptance",
      "When a stroke counts as written: progress along its centre line (the data's median) within a "
      "corridor, with a bounded mean distance, far enough along it. Lengths in m; defaults for a "
      "60 mm character from people's distances to hanzi-writer-data's medians (docs/stroke-acceptance.md).",
      [](const StrokeAcceptance& a) { a.validate(); })
      .field("corridor_m", &StrokeAcceptance::corridor_m,
             "farthest from the centre line that makes progress [m]")
      .field("mean_deviation_m", &StrokeAcceptance::mean_deviation_m,
             "largest mean distance from the centre line over the pen's path [m]")
      .field("shortfall_m", &StrokeAcceptance::shortfall_m,
             "how much shorter than the stroke the pen's way along it may be [m]")
      .field("shortfall_fraction", &StrokeAcceptance::shortfall_fraction,
             "the same as a fraction of the stroke's length, in (0, 1); the smaller applies")
      .field("displacement_m", &StrokeAcceptance::displacement_m,
             "how far a copy may be displaced along the stroke [m]")
      .field("max_gain_ratio", &StrokeAcceptance::max_gain_ratio,
             "most arc credited per length of pen motion, >= 1")
      .field("follow_through_m", &StrokeAcceptance::follow_through_m,
             "radius of the end neighbourhood a pen past the end may move in before it lifts [m]")
      .field("lookahead_m", &StrokeAcceptance::lookahead_m,
             "how far along the line the foot point is looked for around the progress [m]")
      .finish();

  m.def("nearest_point", &nearest_point_py, py::arg("element"), py::arg("point"),
        py::arg("method") = NearestPointMethod::exact, py::arg("tolerance") = 1e-12,
        py::arg("newton_starts") = 8, py::arg("newton_iterations") = 6,
        R"(Nearest point on a stroke element (paper section 4.3).

element: a StrokeElement, or its control points, array-like (n, 2) with n in 2..5.
point: shape (2,) -> returns (t: float, foot: (2,) float64, distance: float);
       shape (N, 2) -> returns (t: (N,), foot: (N, 2), distance: (N,)), float64; the GIL is released
       while the N points are computed.
method: a NearestPointMethod or its name, 'exact' (global, default), 'newton' or 'subdivision'.
tolerance: for 'exact' a parameter interval (dimensionless), for 'subdivision' a length in the
element's units. newton_starts, newton_iterations: 1..1000 ('newton' only).
Lengths are in the units of the control points (m for placed elements).
Raises InvalidArgument (a ValueError) for a non-finite point, bad shapes or options out of range,
TypeError naming the argument for a value of the wrong type.)");
}

}  // namespace calligraphy::python
