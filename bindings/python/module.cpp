// The extension module `calligraphy._calligraphy` (pybind11 + numpy). The package's __init__.py
// re-exports it. Everything is SI: lengths in m, forces in N, time in s, stiffness in N/m, damping in
// N s/m; character data stays in its own units (hanzi-writer-data's 1024 box, y up).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <string>
#include <vector>

#include "calligraphy/collision/nearest_point.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "core/unicode.hpp"

namespace py = pybind11;
using namespace calligraphy;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// ---- small numpy helpers -----------------------------------------------------------------------

py::array_t<double> new_array(std::vector<py::ssize_t> shape) {
  return py::array_t<double>(std::move(shape));
}

py::array_t<double> points_to_array(const Vec2* points, std::size_t count) {
  auto out = new_array({static_cast<py::ssize_t>(count), 2});
  auto w = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < count; ++i) {
    w(static_cast<py::ssize_t>(i), 0) = points[i].x();
    w(static_cast<py::ssize_t>(i), 1) = points[i].y();
  }
  return out;
}

py::array_t<double> vec_to_array(const Vec2& v) {
  auto out = new_array({2});
  out.mutable_at(0) = v.x();
  out.mutable_at(1) = v.y();
  return out;
}

py::array_t<double> vec_to_array(const Vec3& v) {
  auto out = new_array({3});
  for (py::ssize_t i = 0; i < 3; ++i) out.mutable_at(i) = v[static_cast<Eigen::Index>(i)];
  return out;
}

// An array of vectors of length `dim`: shape (dim,) is one vector, (N, dim) are N of them.
struct Vectors {
  Array array;
  bool single = false;
  py::ssize_t count = 0;
  const double* row(py::ssize_t i) const { return array.data() + i * array.shape(array.ndim() - 1); }
};

Vectors as_vectors(const py::object& object, py::ssize_t dim, const char* what) {
  Vectors v{Array::ensure(object)};
  if (!v.array) throw InvalidArgument(std::string(what) + ": expected an array of numbers");
  const py::ssize_t ndim = v.array.ndim();
  if (ndim == 1 && v.array.shape(0) == dim) {
    v.single = true;
    v.count = 1;
  } else if (ndim == 2 && v.array.shape(1) == dim) {
    v.count = v.array.shape(0);
  } else {
    throw InvalidArgument(std::string(what) + ": expected shape (" + std::to_string(dim) + ",) or (N, " +
                          std::to_string(dim) + ")");
  }
  return v;
}

// Scalars: shape () is one, (N,) are N of them.
struct Scalars {
  Array array;
  bool single = false;
  py::ssize_t count = 0;
};

Scalars as_scalars(const py::object& object, const char* what) {
  Scalars s{Array::ensure(object)};
  if (!s.array) throw InvalidArgument(std::string(what) + ": expected a number or an array of numbers");
  if (s.array.ndim() == 0) {
    s.single = true;
    s.count = 1;
  } else if (s.array.ndim() == 1) {
    s.count = s.array.shape(0);
  } else {
    throw InvalidArgument(std::string(what) + ": expected a number or shape (N,)");
  }
  return s;
}

char32_t one_character(const std::string& text) {
  const std::u32string chars = decode_utf8(text);
  if (chars.size() != 1) {
    throw InvalidArgument("expected exactly one character, got " + std::to_string(chars.size()) + " in '" +
                          text + "'");
  }
  return chars[0];
}

// ---- elements ----------------------------------------------------------------------------------

StrokeElement element_from_points(const py::object& object) {
  const Vectors v = as_vectors(object, 2, "control_points");
  if (v.single || v.count < 2 || v.count > kMaxElementDegree + 1) {
    throw InvalidArgument("control_points: expected shape (n, 2) with n in 2..5, got " +
                          std::to_string(v.count) + " point(s)");
  }
  std::vector<Vec2> points;
  for (py::ssize_t i = 0; i < v.count; ++i) points.emplace_back(v.row(i)[0], v.row(i)[1]);
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

StrokeElement element_from(const py::object& object) {
  if (py::isinstance<StrokeElement>(object)) return object.cast<StrokeElement>();
  return element_from_points(object);
}

NearestPointMethod method_from(const std::string& name) {
  if (name == "exact") return NearestPointMethod::exact;
  if (name == "newton") return NearestPointMethod::newton;
  if (name == "subdivision") return NearestPointMethod::subdivision;
  throw InvalidArgument("method: expected 'exact', 'newton' or 'subdivision', got '" + name + "'");
}

py::tuple nearest_point_py(const py::object& element_object, const py::object& point,
                           const std::string& method, double tolerance, int newton_starts,
                           int newton_iterations) {
  const StrokeElement element = element_from(element_object);
  NearestPointOptions options;
  options.method = method_from(method);
  options.tolerance = tolerance;
  options.newton_starts = newton_starts;
  options.newton_iterations = newton_iterations;
  const Vectors p = as_vectors(point, 2, "point");
  if (p.single) {
    const NearestPoint r = nearest_point(element, Vec2(p.row(0)[0], p.row(0)[1]), options);
    return py::make_tuple(r.t, vec_to_array(r.foot), r.distance);
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
      const NearestPoint r = nearest_point(element, Vec2(p.row(i)[0], p.row(i)[1]), options);
      tw(i) = r.t;
      fw(i, 0) = r.foot.x();
      fw(i, 1) = r.foot.y();
      dw(i) = r.distance;
    }
  }
  return py::make_tuple(t, foot, distance);
}

// ---- force law ---------------------------------------------------------------------------------

template <int Dim, typename F>
py::array_t<double> map_vectors(const Vectors& in, F&& f) {
  auto out = in.single ? new_array({Dim}) : new_array({in.count, Dim});
  double* o = out.mutable_data();
  for (py::ssize_t i = 0; i < in.count; ++i) {
    const Eigen::Matrix<double, Dim, 1> r = f(i);
    for (int k = 0; k < Dim; ++k) o[i * Dim + k] = r[k];
  }
  return out;
}

void check_same_count(const Vectors& a, const Vectors& b, const char* what) {
  if (a.count != b.count && b.count != 1) throw InvalidArgument(std::string(what) + ": array lengths differ");
}

// ---- trial -------------------------------------------------------------------------------------

struct PyTrialResult {
  py::array t, position, force, state, active_stroke, active_element;
  py::dict metrics;
};

py::dict metrics_dict(const std::string& characters, bool guidance, const std::string& writer,
                      std::uint64_t seed, double rate_hz, const TrialResult& result) {
  const TrialMetrics& m = result.metrics;
  py::list per_stroke;
  for (const StrokeMetrics& s : m.per_stroke) {
    py::dict d;
    d["index"] = s.index + 1;
    d["typical_id"] = s.typical_id;
    d["mean_deviation_mm"] = s.mean_deviation_m * 1e3;
    d["max_deviation_mm"] = s.max_deviation_m * 1e3;
    d["time_s"] = s.time_s;
    d["completed"] = s.completed;
    d["attempts"] = s.attempts;
    per_stroke.append(d);
  }
  py::dict d;
  d["character"] = characters;
  d["guidance"] = guidance;
  d["writer"] = writer;
  d["seed"] = seed;
  d["rate_hz"] = rate_hz;
  d["device"] = "simulated";  // as `calligraphy trial --device simulated`
  d["aborted"] = result.aborted;
  d["abort_reason"] = result.abort_reason;
  d["end_reason"] = to_string(result.end);
  d["strokes_total"] = m.strokes_total;
  d["strokes_completed"] = m.strokes_completed;
  d["completed_in_order"] = m.completed_in_order;
  d["time_s"] = m.time_s;
  d["mean_deviation_mm"] = m.mean_deviation_m * 1e3;
  d["max_deviation_mm"] = m.max_deviation_m * 1e3;
  d["max_force_n"] = m.max_force_n;
  d["max_force_step_n"] = m.max_force_step_n;
  d["state_transitions"] = m.state_transitions;
  d["per_stroke"] = per_stroke;
  return d;
}

PyTrialResult simulate_trial_py(const py::object& characters_object, const std::string& writer, bool guidance,
                                double rate_hz, std::uint64_t seed, const py::object& library_object,
                                const py::object& force_law_object, double max_duration_s, bool keep_trace) {
  // Characters: a str of one or more characters, a Character, or a sequence of Characters.
  std::vector<Character> characters;
  std::string label;
  if (py::isinstance<py::str>(characters_object)) {
    label = characters_object.cast<std::string>();
    const std::u32string chars = decode_utf8(label);
    if (chars.empty()) throw InvalidArgument("simulate_trial: no character given");
    const CharacterLibrary library =
        library_object.is_none() ? CharacterLibrary::embedded() : library_object.cast<CharacterLibrary>();
    for (char32_t c : chars) characters.push_back(library.load(c));
  } else if (py::isinstance<Character>(characters_object)) {
    characters.push_back(characters_object.cast<Character>());
  } else {
    for (const py::handle item : characters_object) {
      if (!py::isinstance<Character>(item)) {
        throw InvalidArgument("simulate_trial: expected a str, a Character or a sequence of Characters");
      }
      characters.push_back(item.cast<Character>());
    }
    if (characters.empty()) throw InvalidArgument("simulate_trial: no character given");
  }
  if (label.empty()) {
    for (const Character& c : characters) label += encode_utf8(c.code_point);
  }

  TrialOptions options;
  if (!force_law_object.is_none()) options.force = force_law_object.cast<ForceLawParameters>();
  options.force.guidance = guidance;
  if (writer == "novice") {
    options.simulation.writer = WriterProfile::novice();
  } else if (writer == "skilled") {
    options.simulation.writer = WriterProfile::skilled();
  } else {
    throw InvalidArgument("writer: expected 'novice' or 'skilled', got '" + writer + "'");
  }
  options.rate_hz = rate_hz;
  options.simulation.seed = seed;
  options.max_duration_s = max_duration_s;
  options.keep_trace = keep_trace;

  TrialResult result;
  {
    py::gil_scoped_release release;
    const Scene scene = Scene::lay_out(characters);
    result = run_simulated_trial(scene, options);
  }

  const auto n = static_cast<py::ssize_t>(result.trace.size());
  auto t = new_array({n});
  auto position = new_array({n, 3});
  auto force = new_array({n, 3});
  py::array_t<std::uint8_t> state({n});
  py::array_t<std::int64_t> active_stroke({n});
  py::array_t<std::int64_t> active_element({n});
  {
    auto tw = t.mutable_unchecked<1>();
    auto pw = position.mutable_unchecked<2>();
    auto fw = force.mutable_unchecked<2>();
    auto sw = state.mutable_unchecked<1>();
    auto aw = active_stroke.mutable_unchecked<1>();
    auto ew = active_element.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < n; ++i) {
      const TrialSample& s = result.trace[static_cast<std::size_t>(i)];
      tw(i) = s.time_s;
      for (py::ssize_t k = 0; k < 3; ++k) {
        pw(i, k) = s.position_m[static_cast<Eigen::Index>(k)];
        fw(i, k) = s.force_n[static_cast<Eigen::Index>(k)];
      }
      sw(i) = static_cast<std::uint8_t>(s.state);
      aw(i) = static_cast<std::int64_t>(s.stroke);
      ew(i) = static_cast<std::int64_t>(s.element);
    }
  }
  return PyTrialResult{t,
                       position,
                       force,
                       state,
                       active_stroke,
                       active_element,
                       metrics_dict(label, guidance, writer, seed, rate_hz, result)};
}

// ---- exceptions --------------------------------------------------------------------------------

py::object new_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("calligraphy.") + name;
  py::dict dict;
  dict["__doc__"] = doc;
  // Show the C++ message as is (KeyError's own __str__ would quote it).
  dict["__str__"] = py::module_::import("builtins").attr("BaseException").attr("__str__");
  py::object type =
      py::reinterpret_steal<py::object>(PyErr_NewException(qualified.c_str(), bases.ptr(), dict.ptr()));
  if (!type) throw py::error_already_set();
  m.attr(name) = type;
  return type;
}

}  // namespace

PYBIND11_MODULE(_calligraphy, m) {
  m.doc() = "Haptic training of Chinese handwriting (Wang, Zhang & Yao 2006), SI units throughout.";

  // Exceptions. Python classes mirror the C++ hierarchy and the builtin they behave as.
  const py::handle exception = PyExc_Exception;
  static py::object error_type =
      new_exception(m, "CalligraphyError", py::make_tuple(exception),
                    "Base of every error raised by calligraphy (C++ calligraphy::Error).");
  static py::object invalid_type = new_exception(
      m, "InvalidArgumentError", py::make_tuple(error_type, py::handle(PyExc_ValueError)),
      "A value outside a documented precondition (C++ calligraphy::InvalidArgument); a ValueError.");
  static py::object data_type =
      new_exception(m, "DataError", py::make_tuple(error_type, py::handle(PyExc_RuntimeError)),
                    "Character data could not be read (C++ calligraphy::DataError); a RuntimeError.");
  static py::object not_found_type = new_exception(
      m, "CharacterNotFoundError", py::make_tuple(data_type, py::handle(PyExc_KeyError)),
      "A character is not in the library (C++ calligraphy::CharacterNotFound); a KeyError and a DataError.");
  static py::object device_type =
      new_exception(m, "DeviceError", py::make_tuple(error_type, py::handle(PyExc_RuntimeError)),
                    "A haptic-device fault (C++ calligraphy::DeviceError); a RuntimeError.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const CharacterNotFound& e) {
      PyErr_SetString(not_found_type.ptr(), e.what());
    } catch (const DataError& e) {
      PyErr_SetString(data_type.ptr(), e.what());
    } catch (const InvalidArgument& e) {
      PyErr_SetString(invalid_type.ptr(), e.what());
    } catch (const DeviceError& e) {
      PyErr_SetString(device_type.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error_type.ptr(), e.what());
    }
  });

  // Typical strokes.
  py::list typical;
  for (const TypicalStroke& s : typical_strokes()) {
    py::dict d;
    d["id"] = s.id;
    d["acronym"] = std::string(s.acronym);
    d["name"] = std::string(s.name_zh);
    d["pinyin"] = std::string(s.pinyin);
    d["unicode"] = s.unicode != 0 ? py::object(py::str(encode_utf8(s.unicode))) : py::object(py::none());
    d["compound"] = s.compound;
    d["default_attraction"] = s.default_attraction;
    d["corner_attraction"] = s.corner_attraction;
    typical.append(d);
  }
  m.attr("TYPICAL_STROKES") = typical;

  // Interaction states, as stored in TrialResult.state.
  m.attr("STATE_NAMES") = py::make_tuple("SS", "AS", "CS", "WS");
  m.attr("SEPARATION") = static_cast<int>(InteractionState::separation);
  m.attr("ADJUSTING") = static_cast<int>(InteractionState::adjusting);
  m.attr("CALIBRATION") = static_cast<int>(InteractionState::calibration);
  m.attr("WRITING") = static_cast<int>(InteractionState::writing);

  // Elements.
  py::class_<StrokeElement>(
      m, "StrokeElement",
      "A stroke element (paper section 3.2): an LSE (kind 'line', degree 1) or a CSE (kind "
      "'bezier', degree 2..4), in the units of its control points.")
      .def(
          py::init([](const py::object& points) { return element_from_points(points); }),
          py::arg("control_points"),
          "From control points, array-like of shape (n, 2) with n in 2..5: 2 points make a line, 3..5 a "
          "Bezier curve. Raises InvalidArgumentError (a ValueError) otherwise or when a point is not finite.")
      .def_property_readonly(
          "kind", [](const StrokeElement& e) { return e.kind == ElementKind::line ? "line" : "bezier"; })
      .def_readonly("degree", &StrokeElement::degree)
      .def_property_readonly(
          "control_points",
          [](const StrokeElement& e) {
            return points_to_array(e.control.data(), static_cast<std::size_t>(e.point_count()));
          },
          "numpy array (degree + 1, 2), in the element's units")
      .def(
          "point",
          [](const StrokeElement& e, const py::object& t_object) -> py::object {
            const Scalars t = as_scalars(t_object, "t");
            if (t.single) return vec_to_array(e.point(*t.array.data()));
            auto out = new_array({t.count, 2});
            auto w = out.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < t.count; ++i) {
              const Vec2 p = e.point(t.array.data()[i]);
              w(i, 0) = p.x();
              w(i, 1) = p.y();
            }
            return out;
          },
          py::arg("t"), "B(t) for t in [0, 1]: shape (2,) for a number, (N, 2) for an array of shape (N,).")
      .def("arc_length", &StrokeElement::arc_length, "Arc length, in the element's units.")
      .def("__repr__", [](const StrokeElement& e) {
        return std::string("<StrokeElement ") + (e.kind == ElementKind::line ? "line" : "bezier") +
               " degree " + std::to_string(e.degree) + ">";
      });

  m.def("nearest_point", &nearest_point_py, py::arg("element"), py::arg("point"), py::arg("method") = "exact",
        py::arg("tolerance") = 1e-12, py::arg("newton_starts") = 8, py::arg("newton_iterations") = 6,
        R"(Nearest point on a stroke element (paper section 4.3).

element: a StrokeElement, or control points array-like (n, 2), n in 2..5.
point: shape (2,) -> returns (t: float, foot: (2,), distance: float);
       shape (N, 2) -> returns (t: (N,), foot: (N, 2), distance: (N,)).
method: 'exact' (global root isolation, default), 'newton' or 'subdivision' (the paper's greedy search).
tolerance: for 'exact' a parameter interval (dimensionless), for 'subdivision' a length in the
element's units. Lengths are in the units of the control points (m for placed elements).
Raises InvalidArgumentError (ValueError) for a non-finite point, bad shapes or options.)");

  // Characters.
  py::class_<Stroke>(m, "Stroke", "One stroke of a character, in data units (1024 box, y up).")
      .def_readonly("typical_id", &Stroke::typical_id, "typical-stroke ID, 1..39")
      .def_property_readonly(
          "acronym", [](const Stroke& s) { return std::string(typical_stroke(s.typical_id).acronym); })
      .def_readonly("elements", &Stroke::elements, "list of StrokeElement in writing direction")
      .def_property_readonly(
          "attraction_factors",
          [](const Stroke& s) {
            auto out = new_array({static_cast<py::ssize_t>(s.attraction_factors.size())});
            for (std::size_t i = 0; i < s.attraction_factors.size(); ++i) {
              out.mutable_at(static_cast<py::ssize_t>(i)) = s.attraction_factors[i];
            }
            return out;
          },
          "numpy (len(elements) + 1,), dimensionless, one per feature point")
      .def_property_readonly(
          "feature_points",
          [](const Stroke& s) {
            std::vector<Vec2> points;
            for (std::size_t k = 0; k < s.feature_point_count(); ++k) points.push_back(s.feature_point(k));
            return points_to_array(points.data(), points.size());
          },
          "numpy (len(elements) + 1, 2), data units")
      .def_property_readonly(
          "median", [](const Stroke& s) { return points_to_array(s.median.data(), s.median.size()); },
          "the source median polyline, numpy (M, 2), data units")
      .def("__repr__", [](const Stroke& s) {
        return "<Stroke " + std::string(typical_stroke(s.typical_id).acronym) + " (" +
               std::to_string(s.typical_id) + "), " + std::to_string(s.elements.size()) + " element(s)>";
      });

  py::class_<Character>(m, "Character", "A modelled character (paper section 3), data units.")
      .def_property_readonly("char", [](const Character& c) { return encode_utf8(c.code_point); })
      .def_property_readonly("code_point",
                             [](const Character& c) { return static_cast<std::uint32_t>(c.code_point); })
      .def_readonly("source", &Character::source)
      .def_readonly("strokes", &Character::strokes, "list of Stroke in standard stroke order")
      .def_property_readonly(
          "typical_stroke_ids",
          [](const Character& c) {
            std::vector<int> ids;
            for (const Stroke& s : c.strokes) ids.push_back(s.typical_id);
            return ids;
          },
          "list of int, one typical-stroke ID per stroke")
      .def("__len__", [](const Character& c) { return c.strokes.size(); })
      .def("__repr__", [](const Character& c) {
        return "<Character " + encode_utf8(c.code_point) + ", " + std::to_string(c.strokes.size()) +
               " strokes>";
      });

  py::class_<CharacterLibrary>(m, "CharacterLibrary", "A set of hanzi-writer-data characters to load from.")
      .def_static("default", &CharacterLibrary::embedded,
                  "The embedded default set (compiled into the library).")
      .def_static(
          "from_hanzi_writer",
          [](const std::filesystem::path& folder) { return CharacterLibrary::from_directory(folder); },
          py::arg("path"),
          "A folder of hanzi-writer-data '<char>.json' files. Raises DataError (a RuntimeError) when it does "
          "not "
          "exist.")
      .def(
          "load",
          [](const CharacterLibrary& lib, const std::string& c) { return lib.load(one_character(c)); },
          py::arg("char"),
          "The fitted Character for a one-character str. Raises CharacterNotFoundError (a KeyError) when "
          "absent, "
          "DataError for malformed data, InvalidArgumentError (a ValueError) unless exactly one character is "
          "given.")
      .def("__contains__",
           [](const CharacterLibrary& lib, const std::string& c) {
             const std::u32string chars = decode_utf8(c);
             return chars.size() == 1 && lib.contains(chars[0]);
           })
      .def(
          "characters",
          [](const CharacterLibrary& lib) {
            std::vector<std::string> out;
            for (char32_t c : lib.characters()) out.push_back(encode_utf8(c));
            return out;
          },
          "Every available character (list of str), sorted by code point.")
      .def_property_readonly("description", &CharacterLibrary::description)
      .def("__repr__",
           [](const CharacterLibrary& lib) { return "<CharacterLibrary " + lib.description() + ">"; });

  // Force law.
  py::class_<ForceLawParameters>(
      m, "ForceLaw",
      "The force model of paper section 5 (F_e = F_en + F_et, eq. 7), SI units. The "
      "paper plane is z = paper_z_m, +z out of the paper.")
      .def(py::init([](double guidance_stiffness, double paper_stiffness, double radius, double damping,
                       double hysteresis, bool guidance, double taper, double crossfade, double paper_fade,
                       double plane_margin, double paper_damping, double foot_speed, double friction,
                       double stick_speed) {
             ForceLawParameters p;
             p.guidance_stiffness_n_per_m = guidance_stiffness;
             p.paper_stiffness_n_per_m = paper_stiffness;
             p.constraint_radius_m = radius;
             p.resistance_damping_n_s_per_m = damping;
             p.contact_hysteresis_m = hysteresis;
             p.guidance = guidance;
             p.constraint_taper_m = taper;
             p.crossfade_s = crossfade;
             p.paper_fade_s = paper_fade;
             p.feature_plane_margin_m = plane_margin;
             p.paper_damping_n_s_per_m = paper_damping;
             p.max_foot_speed_m_s = foot_speed;
             p.friction_coefficient = friction;
             p.friction_stick_speed_m_s = stick_speed;
             p.validate();
             return p;
           }),
           py::arg("guidance_stiffness_n_per_m") = ForceLawParameters{}.guidance_stiffness_n_per_m,
           py::arg("paper_stiffness_n_per_m") = ForceLawParameters{}.paper_stiffness_n_per_m,
           py::arg("constraint_radius_m") = ForceLawParameters{}.constraint_radius_m,
           py::arg("resistance_damping_n_s_per_m") = ForceLawParameters{}.resistance_damping_n_s_per_m,
           py::arg("contact_hysteresis_m") = ForceLawParameters{}.contact_hysteresis_m,
           py::arg("guidance") = true,
           py::arg("constraint_taper_m") = ForceLawParameters{}.constraint_taper_m,
           py::arg("crossfade_s") = ForceLawParameters{}.crossfade_s,
           py::arg("paper_fade_s") = ForceLawParameters{}.paper_fade_s,
           py::arg("feature_plane_margin_m") = ForceLawParameters{}.feature_plane_margin_m,
           py::arg("paper_damping_n_s_per_m") = ForceLawParameters{}.paper_damping_n_s_per_m,
           py::arg("max_foot_speed_m_s") = ForceLawParameters{}.max_foot_speed_m_s,
           py::arg("friction_coefficient") = ForceLawParameters{}.friction_coefficient,
           py::arg("friction_stick_speed_m_s") = ForceLawParameters{}.friction_stick_speed_m_s,
           "Raises InvalidArgumentError (a ValueError) naming the field when a value is negative or not "
           "finite, the radius or the stick speed is not positive, or the taper is wider than the radius. "
           "The smoothing fields (section 6) and friction: docs/force-rendering.md.")
      .def_readonly("guidance_stiffness_n_per_m", &ForceLawParameters::guidance_stiffness_n_per_m,
                    "K_et [N/m]")
      .def_readonly("paper_stiffness_n_per_m", &ForceLawParameters::paper_stiffness_n_per_m, "K_en [N/m]")
      .def_readonly("constraint_radius_m", &ForceLawParameters::constraint_radius_m, "R_res [m]")
      .def_readonly("resistance_damping_n_s_per_m", &ForceLawParameters::resistance_damping_n_s_per_m,
                    "[N s/m]")
      .def_readonly("contact_hysteresis_m", &ForceLawParameters::contact_hysteresis_m, "[m]")
      .def_readonly("guidance", &ForceLawParameters::guidance)
      .def_readonly("constraint_taper_m", &ForceLawParameters::constraint_taper_m,
                    "band at R_res over which F_et tapers to zero [m]")
      .def_readonly("crossfade_s", &ForceLawParameters::crossfade_s, "in-plane cross-fade time [s]")
      .def_readonly("paper_fade_s", &ForceLawParameters::paper_fade_s,
                    "paper-force fade time (AS <-> CS) [s]")
      .def_readonly("feature_plane_margin_m", &ForceLawParameters::feature_plane_margin_m,
                    "feature-plane hysteresis [m]")
      .def_readonly("paper_damping_n_s_per_m", &ForceLawParameters::paper_damping_n_s_per_m,
                    "paper damping on inward motion [N s/m]")
      .def_readonly("max_foot_speed_m_s", &ForceLawParameters::max_foot_speed_m_s,
                    "highest speed of the attraction target X_S [m/s]")
      .def_readonly("friction_coefficient", &ForceLawParameters::friction_coefficient, "Coulomb mu")
      .def_readonly("friction_stick_speed_m_s", &ForceLawParameters::friction_stick_speed_m_s,
                    "stick band of the friction [m/s]")
      .def(
          "paper_force",
          [](const ForceLawParameters& p, const py::object& z_object, double paper_z) -> py::object {
            const Scalars z = as_scalars(z_object, "tip_z_m");
            auto out = z.single ? new_array({3}) : new_array({z.count, 3});
            double* o = out.mutable_data();
            for (py::ssize_t i = 0; i < z.count; ++i) {
              const Vec3 f = paper_force(z.array.data()[i], paper_z, p.paper_stiffness_n_per_m);
              for (int k = 0; k < 3; ++k) o[i * 3 + k] = f[k];
            }
            return out;
          },
          py::arg("tip_z_m"), py::arg("paper_z_m") = 0.0,
          "Eq. (9): K_en (z0 - z) e_z below the paper, else 0 [N]. tip_z_m: number -> (3,), shape (N,) -> "
          "(N, 3).")
      .def(
          "attraction_force",
          [](const ForceLawParameters& p, const py::object& tip_object, const py::object& foot_object,
             double factor) -> py::object {
            const Vectors tip = as_vectors(tip_object, 2, "tip_m");
            const Vectors foot = as_vectors(foot_object, 2, "foot_m");
            check_same_count(tip, foot, "attraction_force");
            return map_vectors<2>(tip, [&](py::ssize_t i) {
              const double* f = foot.row(foot.count == 1 ? 0 : i);
              return attraction_force(Vec2(tip.row(i)[0], tip.row(i)[1]), Vec2(f[0], f[1]),
                                      p.guidance_stiffness_n_per_m, factor);
            });
          },
          py::arg("tip_m"), py::arg("foot_m"), py::arg("attraction_factor") = 1.0,
          "Eq. (8), attracting: K_et a (X_S - X_p) [N] in the paper plane. tip_m (2,) or (N, 2) [m], foot_m "
          "the "
          "foot point X_S, same shape or (2,) [m]; returns the tip's shape.")
      .def(
          "resistance_force",
          [](const ForceLawParameters& p, const py::object& v_object,
             const py::object& tangent_object) -> py::object {
            const Vectors v = as_vectors(v_object, 2, "velocity_m_s");
            const Vectors tangent = as_vectors(tangent_object, 2, "tangent");
            check_same_count(v, tangent, "resistance_force");
            return map_vectors<2>(v, [&](py::ssize_t i) {
              const double* tg = tangent.row(tangent.count == 1 ? 0 : i);
              return resistance_force(Vec2(v.row(i)[0], v.row(i)[1]), Vec2(tg[0], tg[1]),
                                      p.resistance_damping_n_s_per_m);
            });
          },
          py::arg("velocity_m_s"), py::arg("tangent"),
          "Resistance against writing backwards: -b (v.t) t when v.t < 0, else 0 [N]. velocity_m_s (2,) or "
          "(N, 2) "
          "[m/s]; tangent the unit writing direction, same shape or (2,).")
      .def_static(
          "clamp",
          [](const py::object& force_object, double max_force_n) -> py::object {
            const Vectors f = as_vectors(force_object, 3, "force_n");
            return map_vectors<3>(f, [&](py::ssize_t i) {
              return clamp_force(Vec3(f.row(i)[0], f.row(i)[1], f.row(i)[2]), max_force_n);
            });
          },
          py::arg("force_n"), py::arg("max_force_n"),
          "Scales each force (3,) or (N, 3) [N] down to at most max_force_n, keeping its direction; a "
          "non-finite "
          "force gives zero.")
      .def("__repr__", [](const ForceLawParameters& p) {
        return "<ForceLaw K_et=" + std::to_string(p.guidance_stiffness_n_per_m) +
               " N/m K_en=" + std::to_string(p.paper_stiffness_n_per_m) +
               " N/m R_res=" + std::to_string(p.constraint_radius_m) + " m>";
      });

  // Trials.
  py::class_<PyTrialResult>(
      m, "TrialResult",
      "A simulated trial. Arrays have one row per servo tick (N ticks). state holds ints: "
      "0 SS, 1 AS, 2 CS, 3 WS (STATE_NAMES[i]).")
      .def_readonly("t", &PyTrialResult::t, "(N,) time [s]")
      .def_readonly("position", &PyTrialResult::position, "(N, 3) pen tip as read from the device [m]")
      .def_readonly("force", &PyTrialResult::force, "(N, 3) commanded force [N]")
      .def_readonly("state", &PyTrialResult::state, "(N,) uint8 interaction state, see STATE_NAMES")
      .def_readonly("active_stroke", &PyTrialResult::active_stroke,
                    "(N,) active stroke over the scene, 0-based")
      .def_readonly("active_element", &PyTrialResult::active_element, "(N,) active element in it, 0-based")
      .def_readonly(
          "metrics", &PyTrialResult::metrics,
          "dict with the keys of `calligraphy trial --json` (deviations in mm, times in s, forces in N)");

  m.def("simulate_trial", &simulate_trial_py, py::arg("characters"), py::arg("writer") = "novice",
        py::arg("guidance") = true, py::arg("rate_hz") = 1000.0, py::arg("seed") = 0,
        py::arg("library") = py::none(), py::arg("force_law") = py::none(), py::arg("max_duration_s") = 300.0,
        py::arg("keep_trace") = true,
        R"(Runs a whole guided writing trial lock-step on the simulated device with a simulated writer,
as `calligraphy trial` does. Deterministic for a seed; the GIL is released while it runs.

characters: a str of one or more characters (loaded from `library`, default the embedded set),
            a Character, or a list of Characters (written left to right).
writer: 'novice' or 'skilled'. guidance: in-plane guidance on or off (the paper force stays).
rate_hz: servo rate [Hz], 100..100000. max_duration_s: simulated time limit [s].
force_law: a ForceLaw for the parameters (its `guidance` is replaced by `guidance`).
keep_trace: False leaves the arrays empty (faster, metrics only).
Returns a TrialResult. Raises CharacterNotFoundError (KeyError), InvalidArgumentError (ValueError).)");

  // Simulated device.
  py::class_<DeviceState>(m, "DeviceState", "A device snapshot, SI units.")
      .def_property_readonly(
          "position", [](const DeviceState& s) { return vec_to_array(s.position_m); },
          "(3,) tip position [m]")
      .def_property_readonly(
          "velocity", [](const DeviceState& s) { return vec_to_array(s.velocity_m_s); },
          "(3,) tip velocity [m/s]")
      .def_readonly("buttons", &DeviceState::buttons)
      .def_readonly("time_s", &DeviceState::time_s, "device time [s]");

  py::class_<SimulatedDevice>(
      m, "SimulatedDevice",
      "A simulated Phantom Desktop: a damped point mass pushed by the commanded force "
      "(zero-order hold, saturated at max_force_n), no hand attached.")
      .def(py::init([](double mass, double damping, double resolution, const py::object& initial) {
             SimulatedDeviceParameters p;
             p.moving_mass_kg = mass;
             p.damping_n_s_per_m = damping;
             p.encoder_resolution_m = resolution;
             const Vectors v = as_vectors(initial, 3, "initial_position_m");
             if (!v.single) throw InvalidArgument("initial_position_m: expected shape (3,)");
             p.initial_position_m = Vec3(v.row(0)[0], v.row(0)[1], v.row(0)[2]);
             p.validate();
             auto device = std::make_unique<SimulatedDevice>(p);
             device->open();
             return device;
           }),
           py::arg("moving_mass_kg") = SimulatedDeviceParameters{}.moving_mass_kg,
           py::arg("damping_n_s_per_m") = SimulatedDeviceParameters{}.damping_n_s_per_m,
           py::arg("encoder_resolution_m") = SimulatedDeviceParameters{}.encoder_resolution_m,
           py::arg("initial_position_m") = py::make_tuple(0.0, -0.05, 0.02),
           "Mass [kg], damping [N s/m], encoder quantum [m], start position (3,) [m]. Opened on creation. "
           "Raises "
           "InvalidArgumentError (ValueError) for out-of-range values.")
      .def("read_state", &SimulatedDevice::read_state, "The DeviceState (position quantised to the encoder).")
      .def(
          "write_force",
          [](SimulatedDevice& d, const py::object& force) {
            const Vectors f = as_vectors(force, 3, "force_n");
            if (!f.single) throw InvalidArgument("force_n: expected shape (3,)");
            d.write_force(Vec3(f.row(0)[0], f.row(0)[1], f.row(0)[2]));
          },
          py::arg("force_n"), "Commands a force (3,) [N], held until the next command.")
      .def(
          "advance",
          [](SimulatedDevice& d, double dt) {
            if (!(dt >= 0.0)) throw InvalidArgument("advance: dt_s must be >= 0");
            d.advance(dt);
          },
          py::arg("dt_s"), "Integrates the physics over dt_s [s].")
      .def("enable_forces", &SimulatedDevice::enable_forces, py::arg("enabled"))
      .def_property_readonly("forces_enabled", &SimulatedDevice::forces_enabled)
      .def_property_readonly(
          "true_position", [](const SimulatedDevice& d) { return vec_to_array(d.true_position()); },
          "(3,) unquantised position [m]")
      .def_property_readonly(
          "true_velocity", [](const SimulatedDevice& d) { return vec_to_array(d.true_velocity()); },
          "(3,) velocity [m/s]")
      .def_property_readonly(
          "applied_force", [](const SimulatedDevice& d) { return vec_to_array(d.applied_force()); },
          "(3,) force applied after saturation [N]")
      .def_property_readonly("time", &SimulatedDevice::time, "[s]")
      .def_property_readonly(
          "max_force_n", [](const SimulatedDevice& d) { return d.info().max_force_n; }, "[N]");
}
