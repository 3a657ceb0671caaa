// collision: the nearest point on a stroke element (include/calligraphy/model/nearest_point.hpp,
// paper section 4.3) and its options; stroke acceptance and the stroke matcher (stroke_progress.hpp,
// stroke_matcher.hpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
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

// The class NearestPointOptions is a force law's `nearest` (its only use), so its tolerance has the force
// law's range, the one a trial record's schema states; nearest_point's own `tolerance=` takes any > 0.
void check_class_options(const NearestPointOptions& o) {
  check_options(o, "NearestPointOptions.");
  check_parameter("NearestPointOptions.tolerance", o.tolerance, "", kForceLawNearestToleranceRange);
}

StrokeElement element_from(py::handle object) {
  if (py::isinstance<StrokeElement>(object)) return object.cast<StrokeElement>();
  return element_from_points(object, "element");
}

py::tuple nearest_point_py(const ElementLike& element_object, const ArrayLike& point,
                           const PyArgument<NearestPointMethod>& method, const PyArgument<double>& tolerance,
                           const PyArgument<int>& newton_starts, const PyArgument<int>& newton_iterations) {
  const StrokeElement element = element_from(element_object.object);
  NearestPointOptions options;
  options.method = take(method, "method");
  options.tolerance = take(tolerance, "tolerance");
  options.newton_starts = take(newton_starts, "newton_starts");
  options.newton_iterations = take(newton_iterations, "newton_iterations");
  check_options(options, "");
  const Vectors p = as_vectors(point.object, 2, "point");
  // Named by the argument and row here; the library's own message names its C++ parameter.
  for (py::ssize_t i = 0; i < p.count; ++i) {
    const Vec2 v = p.vec2(i);
    if (!(std::abs(v.x()) <= kMaxNearestPointCoordinate && std::abs(v.y()) <= kMaxNearestPointCoordinate)) {
      throw InvalidArgument(std::string(p.single ? "point" : "point[" + std::to_string(i) + "]") + " = (" +
                            shortest_decimal(v.x()) + ", " + shortest_decimal(v.y()) +
                            ") is not finite or exceeds 1e150 in magnitude");
    }
  }
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

// A pen-down path (N, 2) [m], N >= 1, every point finite.
std::vector<Vec2> path_from(py::handle object) {
  const Vectors v = as_vectors(object, 2, "path_m");
  if (v.single) throw InvalidArgument("path_m: expected shape (N, 2), got (2,); one point is [[x, y]]");
  if (v.count == 0) throw InvalidArgument("path_m: expected at least one point, got shape (0, 2)");
  std::vector<Vec2> path;
  path.reserve(static_cast<std::size_t>(v.count));
  for (py::ssize_t i = 0; i < v.count; ++i) {
    path.push_back(v.vec2(i));
    if (!path.back().allFinite())
      throw InvalidArgument("path_m: point " + std::to_string(i) + " is not finite");
  }
  return path;
}

StrokeMatch match_stroke_py(const PyArgument<Scene>& scene_object,
                            const PyArgument<long long>& character_index,
                            const PyArgument<long long>& stroke_index, const ArrayLike& path_object,
                            const std::optional<PyArgument<StrokeAcceptance>>& acceptance_object) {
  const StrokeOfScene target = stroke_of_scene(scene_object, character_index, stroke_index);
  const PlacedCharacter& character = target.character;
  const std::size_t stroke = target.stroke;
  const Scene& scene = scene_object.object.cast<const Scene&>();
  const std::vector<Vec2> path_m = path_from(path_object.object);
  const StrokeAcceptance acceptance =
      acceptance_object ? take(*acceptance_object, "acceptance") : StrokeAcceptance{};
  const double start_radius_m = scene.layout.start_radius_m;
  // Long enough for other Python threads to run meanwhile: the path is read in 0.25 mm steps, on every
  // stroke of the character and reversed.
  py::gil_scoped_release release;
  return match_stroke(character, stroke, path_m, start_radius_m, acceptance);
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

  ParameterClass<NearestPointOptions>(m, "NearestPointOptions",
                                      "Options of nearest_point and of the renderer's foot-point search. "
                                      "Lengths are in the element's units (m for a placed element).",
                                      check_class_options)
      .field("method", &NearestPointOptions::method, "a NearestPointMethod (or its name)")
      .field("tolerance", &NearestPointOptions::tolerance,
             "'exact': parameter interval (dimensionless, in t); 'subdivision': the paper's e, a length "
             "(element units). In (0, 0.001], a force law's range")
      .field("newton_starts", &NearestPointOptions::newton_starts, "'newton' only: starts, 1..1000")
      .field("newton_iterations", &NearestPointOptions::newton_iterations,
             "'newton' only: iterations per start, 1..1000")
      .finish();

  ParameterClass<StrokeAcceptance>(
      m, "StrokeAcceptance",
      "When a stroke counts as written: progress along its centre line (the data's median) within a "
      "corridor, with a bounded mean distance, far enough along it; tolerances that grow with the stroke's "
      "length up to a cap, and the misses after which a stroke is hinted and credited as assisted. Lengths "
      "in m; defaults for a 60 mm character, scaled with the character's size, from people's distances to "
      "hanzi-writer-data's medians (docs/stroke-acceptance.md).",
      [](const StrokeAcceptance& a) { a.validate(); })
      .field(&StrokeAcceptance::corridor_m)
      .field(&StrokeAcceptance::mean_deviation_m)
      .field(&StrokeAcceptance::shortfall_m)
      .field(&StrokeAcceptance::shortfall_fraction)
      .field(&StrokeAcceptance::displacement_m)
      .field(&StrokeAcceptance::max_gain_ratio)
      .field(&StrokeAcceptance::follow_through_m)
      .field(&StrokeAcceptance::lookahead_m)
      .field(&StrokeAcceptance::shortfall_per_length)
      .field(&StrokeAcceptance::shortfall_cap_m)
      .field(&StrokeAcceptance::deviation_per_length)
      .field(&StrokeAcceptance::mean_deviation_cap_m)
      .field(&StrokeAcceptance::reference_character_size_m)
      .field(&StrokeAcceptance::hint_after_misses)
      .field(&StrokeAcceptance::assist_after_misses)
      .field(&StrokeAcceptance::end_gap_m)
      .field(&StrokeAcceptance::end_gap_fraction)
      .field(&StrokeAcceptance::centred_coverage_fraction)
      .field(&StrokeAcceptance::centred_balance_fraction)
      .field(&StrokeAcceptance::centred_min_length_m)
      .field(&StrokeAcceptance::centred_max_length_m)
      .field(&StrokeAcceptance::miss_min_path_m)
      .finish();

  py::enum_<StrokeRefusal>(m, "StrokeRefusal",
                           "Why a stroke attempt was not accepted, in the learner's terms "
                           "(include/calligraphy/model/stroke_progress.hpp).")
      .value("none", StrokeRefusal::none, "accepted")
      .value("too_short", StrokeRefusal::too_short,
             "went along the stroke but stopped before its end neighbourhood")
      .value("backwards", StrokeRefusal::backwards, "written from its end towards its start")
      .value("wrong_place", StrokeRefusal::wrong_place,
             "not along the stroke: started elsewhere, or too far from it on average")
      .value("wrong_stroke", StrokeRefusal::wrong_stroke,
             "another stroke's shape, or a stroke of the character already written")
      .value("wrong_order", StrokeRefusal::wrong_order, "a stroke of the character that comes later");

  py::class_<StrokeMatch>(m, "StrokeMatch",
                          "The verdict of match_stroke on one pen-down path "
                          "(include/calligraphy/analysis/stroke_matcher.hpp).")
      .def_readonly("accepted", &StrokeMatch::accepted, "the path writes the expected stroke")
      .def_readonly("refusal", &StrokeMatch::refusal, "a StrokeRefusal, StrokeRefusal.none when accepted")
      .def_readonly("matched_stroke", &StrokeMatch::matched_stroke,
                    "for wrong_order and wrong_stroke the index of the stroke the path writes instead; "
                    "otherwise the expected stroke's index")
      .def_readonly("entered", &StrokeMatch::entered,
                    "the path came within the start radius of the expected stroke's start; when not, "
                    "covered_fraction and mean_deviation_m are 0 and measure nothing")
      .def_readonly("covered_fraction", &StrokeMatch::covered_fraction,
                    "the pen's way along the expected stroke / its length, in [0, 1]")
      .def_readonly("mean_deviation_m", &StrokeMatch::mean_deviation_m,
                    "mean distance of the path from the expected stroke's centre line [m]")
      .def("__repr__", [](const StrokeMatch& s) {
        return std::string("<StrokeMatch ") + (s.accepted ? "accepted" : to_string(s.refusal)) + ", stroke " +
               std::to_string(s.matched_stroke) + ", covered " + shortest_decimal(s.covered_fraction) +
               (s.entered ? ", mean deviation " + shortest_decimal(s.mean_deviation_m) + " m>"
                          : ", never entered>");
      });

  m.def("match_stroke", &match_stroke_py, py::arg("scene"), py::arg("character_index"),
        py::arg("stroke_index"), py::arg("path_m"), py::arg("acceptance") = py::none(),
        R"(Whether one pen-down path writes stroke `stroke_index` of character `character_index` of `scene`
(taking the strokes before it as written), and if not, why (include/calligraphy/analysis/stroke_matcher.hpp).
It is the renderer's rule: the path enters the stroke where it first comes within
scene.layout.start_radius_m of the stroke's start (WS), progress is tracked along the stroke's centre
line, and the path's end is the pen's lift, so a Renderer whose pen moves along the same path (points at
most 0.25 mm apart, one per tick: how the matcher reads it) writes the stroke exactly when this accepts
it. A refusal is named by trying the path on the character's other strokes and reversed.

path_m: array-like (N, 2), N >= 1, points on the paper in writing order [m], at any spacing (read as
        straight lines between them).
acceptance: a StrokeAcceptance (default: the C++ defaults, as ForceLawParameters().acceptance).
Returns a StrokeMatch: accepted (bool), refusal (StrokeRefusal), matched_stroke (int), entered (bool: the
path came near the expected stroke's start), covered_fraction (float, in [0, 1]), mean_deviation_m (float)
[m] (both 0, measuring nothing, when not entered; `score` then gives the verdict's mean_deviation_m None). The GIL is released while matching.
Raises IndexError naming character_index or stroke_index out of range, InvalidArgument (a ValueError)
naming path_m for another shape, no points or a point that is not finite, TypeError naming the argument
for a value of the wrong type.)");

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
