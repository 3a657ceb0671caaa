// model: stroke elements, strokes, characters and their libraries, the typical strokes
// (include/calligraphy/model/). Character data is in its own units: hanzi-writer-data's 1024 box, y up.
#include "model_bindings.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "character_source.hpp"
#include "core/unicode.hpp"
#include "numpy_arrays.hpp"

namespace calligraphy::python {

StrokeElement element_from_points(py::handle object, const std::string& name) {
  const Vectors v = as_vectors(object, 2, name);
  if (v.single || v.count < 2 || v.count > kMaxElementDegree + 1) {
    throw InvalidArgument(name + ": expected shape (n, 2) with n in 2..5, got " + std::to_string(v.count) +
                          " point(s)");
  }
  std::vector<Vec2> points;
  for (py::ssize_t i = 0; i < v.count; ++i) points.push_back(v.vec2(i));
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

namespace {

const char* kind_name(const StrokeElement& e) { return e.kind == ElementKind::line ? "line" : "bezier"; }

void bind_element(py::module_& m) {
  py::class_<StrokeElement>(
      m, "StrokeElement",
      "A stroke element (paper section 3.2): an LSE (kind 'line', degree 1) or a CSE (kind 'bezier', "
      "degree 2..4), in the units of its control points (data units for a Character's, m for a "
      "Scene's).")
      .def(py::init(
               [](const ArrayLike& points) { return element_from_points(points.object, "control_points"); }),
           py::arg("control_points"),
           "From control points, array-like of shape (n, 2) with n in 2..5: 2 points make a line, 3..5 a "
           "Bezier curve. Raises InvalidArgument (a ValueError) otherwise or when a point is not finite, "
           "TypeError when it is not numbers.")
      .def_property_readonly("kind", &kind_name, "'line' (LSE) or 'bezier' (CSE)")
      .def_readonly("degree", &StrokeElement::degree, "1 for a line, 2..4 for a Bezier curve")
      .def_property_readonly(
          "control_points",
          [](const StrokeElement& e) {
            return read_only(points_to_array(e.control.data(), static_cast<std::size_t>(e.point_count())));
          },
          "(degree + 1, 2) float64, in the element's units")
      .def(
          "point",
          [](const StrokeElement& e, const ArrayLike& t_object) -> py::object {
            const Scalars t = as_scalars(t_object.object, "t");
            if (t.single) return to_array(e.point(*t.array.data()));
            auto out = new_array({t.count, 2});
            auto w = out.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < t.count; ++i) {
              const Vec2 p = e.point(t.array.data()[i]);
              w(i, 0) = p.x();
              w(i, 1) = p.y();
            }
            return out;
          },
          py::arg("t"),
          "B(t) for t in [0, 1] (dimensionless): shape (2,) for a number, (N, 2) for an array of shape "
          "(N,), float64, in the element's units.")
      .def("arc_length", &StrokeElement::arc_length, "Arc length, in the element's units.")
      .def("__repr__", [](const StrokeElement& e) {
        return std::string("<StrokeElement ") + kind_name(e) + " degree " + std::to_string(e.degree) + ">";
      });
}

void bind_typical_strokes(py::module_& m) {
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
}

void bind_character(py::module_& m) {
  py::class_<Stroke>(m, "Stroke", "One stroke of a character, in data units (1024 box, y up).")
      .def_readonly("typical_id", &Stroke::typical_id, "typical-stroke ID, 1..39")
      .def_property_readonly(
          "acronym", [](const Stroke& s) { return std::string(typical_stroke(s.typical_id).acronym); },
          "the typical stroke's acronym, e.g. 'HZG'")
      .def_readonly("elements", &Stroke::elements, "list of StrokeElement in writing direction")
      .def_property_readonly(
          "attraction_factors",
          [](const Stroke& s) {
            auto out = new_array({static_cast<py::ssize_t>(s.attraction_factors.size())});
            for (std::size_t i = 0; i < s.attraction_factors.size(); ++i) {
              out.mutable_at(static_cast<py::ssize_t>(i)) = s.attraction_factors[i];
            }
            return read_only(out);
          },
          "(len(elements) + 1,) float64, dimensionless, one per feature point (paper eq. 8)")
      .def_property_readonly(
          "feature_points",
          [](const Stroke& s) {
            std::vector<Vec2> points;
            for (std::size_t k = 0; k < s.feature_point_count(); ++k) points.push_back(s.feature_point(k));
            return read_only(points_to_array(points));
          },
          "(len(elements) + 1, 2) float64, data units: the element joints")
      .def_property_readonly(
          "median", [](const Stroke& s) { return read_only(points_to_array(s.median)); },
          "(M, 2) float64, data units: the source median polyline (empty for a corpus store's character)")
      .def("__repr__", [](const Stroke& s) {
        return "<Stroke " + std::string(typical_stroke(s.typical_id).acronym) + " (" +
               std::to_string(s.typical_id) + "), " + std::to_string(s.elements.size()) + " element(s)>";
      });

  py::class_<Character>(m, "Character",
                        "A modelled character (paper section 3), data units (1024 box, y up).")
      .def_property_readonly(
          "char", [](const Character& c) { return encode_utf8(c.code_point); }, "the character, a str")
      .def_property_readonly(
          "code_point", [](const Character& c) { return static_cast<std::uint32_t>(c.code_point); },
          "its Unicode code point, an int")
      .def_readonly("source", &Character::source, "where the data came from (file path or 'embedded:...')")
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
}

void bind_library(py::module_& m) {
  py::class_<CharacterSource>(m, "CharacterLibrary",
                              "A set of characters to load: the embedded default set or a folder of "
                              "hanzi-writer-data files.")
      .def_static("default", &CharacterSource::embedded,
                  "The embedded default set: a subset of hanzi-writer-data 2.0.1 compiled into the library.")
      .def_static(
          "from_hanzi_writer",
          [](const Checked<std::filesystem::path>& folder) {
            return CharacterSource::hanzi_writer_folder(take(folder, "path"));
          },
          py::arg("path"),
          "A folder of hanzi-writer-data '<char>.json' files (fitted when loaded). Raises DataError (a "
          "RuntimeError) when it does not exist.")
      .def(
          "load",
          [](const CharacterSource& lib, const Checked<std::string>& c) {
            return lib.load(one_character(take(c, "char"), "char"));
          },
          py::arg("char"),
          "The Character for a one-character str. Raises CharacterNotFound (a KeyError) when absent, "
          "DataError for malformed data, InvalidArgument (a ValueError) unless exactly one character is "
          "given, TypeError for a non-str.")
      .def("__contains__",
           [](const CharacterSource& lib, const py::object& c) {
             if (!py::isinstance<py::str>(c)) return false;
             const std::u32string chars = decode_utf8(c.cast<std::string>());
             return chars.size() == 1 && lib.contains(chars[0]);
           })
      .def(
          "characters",
          [](const CharacterSource& lib) {
            std::vector<std::string> out;
            for (char32_t c : lib.characters()) out.push_back(encode_utf8(c));
            return out;
          },
          "Every available character (list of str), sorted by code point.")
      .def_property_readonly("description", &CharacterSource::description, "what the library reads")
      .def("__repr__",
           [](const CharacterSource& lib) { return "<CharacterLibrary " + lib.description() + ">"; });
}

}  // namespace

void bind_model(py::module_& m) {
  bind_element(m);
  bind_typical_strokes(m);
  bind_character(m);
  bind_library(m);
}

}  // namespace calligraphy::python
