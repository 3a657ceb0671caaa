// model: stroke elements, strokes, characters and their libraries, the typical strokes
// (include/calligraphy/model/). Character data is in its own units: hanzi-writer-data's 1024 box, y up.
#include "model_bindings.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "character_source.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {

StrokeElement element_from_points(py::handle object, const std::string& name) {
  const Vectors v = as_vectors(object, 2, name);
  if (v.single || v.count < 2 || v.count > kMaxElementDegree + 1) {
    throw InvalidArgument(name + ": expected shape (n, 2) with n in 2..5, got " + std::to_string(v.count) +
                          " point(s)");
  }
  std::vector<Vec2> points;
  for (py::ssize_t i = 0; i < v.count; ++i) {
    points.push_back(v.vec2(i));
    // Named as Python names it (the argument and the row), not as the C++ constructor would.
    if (!points.back().allFinite())
      throw InvalidArgument(name + ": point " + std::to_string(i) + " is not finite");
  }
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

std::vector<Character> characters_from(py::handle object, const CharacterSource& library,
                                       const std::string& name) {
  std::vector<Character> characters;
  if (py::isinstance<py::str>(object)) {
    const std::u32string text = decode_utf8(convert_named<std::string>(object, name));
    check_scene_size(text.size(), name);   // before loading any
    std::map<char32_t, Character> loaded;  // each character loaded once
    for (char32_t c : text) {
      auto found = loaded.find(c);
      if (found == loaded.end()) found = loaded.emplace(c, library.load(c)).first;
      characters.push_back(found->second);
    }
  } else if (py::isinstance<Character>(object)) {
    characters.push_back(object.cast<Character>());
  } else if (py::isinstance<py::sequence>(object) && !py::isinstance<py::bytes>(object)) {
    check_scene_size(py::len(object), name);
    std::size_t index = 0;
    for (const py::handle item : object) {
      // The item at fault, by its index: the sequence itself is of a type this argument takes.
      if (!py::isinstance<Character>(item)) {
        throw_type_error(name + "[" + std::to_string(index) + "]",
                         "a Character (a sequence holds Characters; characters as text are one str)", item);
      }
      ++index;
      characters.push_back(item.cast<Character>());
    }
  } else {
    throw_type_error(name, "a str, a Character or a sequence of Characters", object);
  }
  if (characters.empty()) throw InvalidArgument(name + ": no character given");
  return characters;
}

namespace {

const char* kind_name(const StrokeElement& e) { return e.kind == ElementKind::line ? "line" : "bezier"; }

void bind_element(py::module_& m) {
  py::class_<StrokeElement>(
      m, "StrokeElement",
      "A stroke element (paper section 3.2): an LSE (kind 'line', degree 1) or a CSE (kind 'bezier', "
      "degree 2..4), in the units of its control points (data units for a Character's, m for a "
      "Scene's).")
      .def(
          py::init(
              [](const ArrayLike& points) { return element_from_points(points.object, "control_points"); }),
          py::arg("control_points"),
          "From control points, array-like of shape (n, 2) with n in 2..5: 2 points make a line, 3..5 a "
          "Bezier curve. Raises InvalidArgument (a ValueError) naming control_points otherwise, when a point "
          "is not finite or when the array holds no real numbers (text, complex), TypeError naming it for a "
          "value that is no array (None, a str).")
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
          [](const StrokeElement& e, const ArrayLike& t_object) -> py::array_t<double> {
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

const TypicalStroke& typical_stroke_by_key(py::handle key) {
  if (py::isinstance<py::str>(key)) {
    const std::string acronym = convert_named<std::string>(key, "key");  // a lone surrogate: a wrong value
    if (const auto id = typical_stroke_id_by_name(acronym)) return typical_stroke(*id);
    std::string known;
    for (const TypicalStroke& t : typical_strokes()) {
      if (!known.empty()) known += ", ";
      known += t.acronym;
    }
    throw InvalidArgument("key: no typical stroke has the acronym, name or stroke character '" + acronym +
                          "'; acronyms: " + known);
  }
  if (PyIndex_Check(key.ptr()) && !PyBool_Check(key.ptr())) {
    const py::object id = py::reinterpret_steal<py::object>(PyNumber_Index(key.ptr()));
    if (!id) throw py::error_already_set();
    if (id < py::int_(1) || id > py::int_(typical_strokes().size())) {  // any int, however large
      throw InvalidArgument("key: typical-stroke ID " + short_repr(id) + " is not in 1.." +
                            std::to_string(typical_strokes().size()));
    }
    return typical_stroke(id.cast<int>());
  }
  throw_type_error("key", "a typical-stroke ID (int) or acronym (str)", key);
}

struct OptionalDictTag {
  static constexpr auto name = py::detail::const_name("Optional[dict]");
};

struct TypicalStrokeKeyTag {
  static constexpr auto name = py::detail::const_name("Union[int, str]");
};

void bind_typical_strokes(py::module_& m) {
  py::class_<StrokePieceTemplate>(
      m, "StrokePieceTemplate",
      "One piece of a typical stroke's element template, corner to corner. Directions are the pen's "
      "direction of motion in degrees in the data's y-up frame (0 = right, 90 = up), lengths in data "
      "units (1024 box).")
      .def_property_readonly(
          "kind",
          [](const StrokePieceTemplate& p) { return p.kind == ElementKind::line ? "line" : "bezier"; },
          "'line' (LSE) where straight, 'bezier' (CSE) where bent")
      .def_readonly("start_direction_deg", &StrokePieceTemplate::start_direction_deg,
                    "nominal start direction [deg]")
      .def_readonly("end_direction_deg", &StrokePieceTemplate::end_direction_deg,
                    "nominal end direction [deg]")
      .def_readonly("start_tolerance_deg", &StrokePieceTemplate::start_tolerance_deg,
                    "one standard deviation of the start direction [deg]")
      .def_readonly("end_tolerance_deg", &StrokePieceTemplate::end_tolerance_deg,
                    "one standard deviation of the end direction [deg]")
      .def_readonly("hook", &StrokePieceTemplate::hook, "a hook or tick: short compared with the stroke")
      .def_readonly("min_length", &StrokePieceTemplate::min_length, "expected least length [data units]")
      .def_readonly("max_length", &StrokePieceTemplate::max_length,
                    "expected greatest length [data units], may be inf")
      .def("__repr__", [](const StrokePieceTemplate& p) {
        return std::string("<StrokePieceTemplate ") + (p.kind == ElementKind::line ? "line" : "bezier") +
               " " + std::to_string(static_cast<int>(p.start_direction_deg)) + " -> " +
               std::to_string(static_cast<int>(p.end_direction_deg)) + " deg" + (p.hook ? ", hook" : "") +
               ">";
      });

  py::class_<TypicalStroke>(m, "TypicalStroke",
                            "One of the 39 typical strokes (paper section 3.1, Fig. 7): the 31 strokes of GF "
                            "2001-2001 and 8 common variants. IDs never change.")
      .def_readonly("id", &TypicalStroke::id, "1..39")
      .def_property_readonly(
          "acronym", [](const TypicalStroke& t) { return std::string(t.acronym); }, "e.g. 'HZG'")
      .def_property_readonly(
          "name_zh", [](const TypicalStroke& t) { return std::string(t.name_zh); }, "e.g. '横折钩'")
      .def_property_readonly(
          "pinyin", [](const TypicalStroke& t) { return std::string(t.pinyin); }, "e.g. 'héng zhé gōu'")
      .def_property_readonly(
          "unicode",
          [](const TypicalStroke& t) -> std::optional<std::string> {
            if (t.unicode == 0) return std::nullopt;
            return encode_utf8(t.unicode);
          },
          "its character in the CJK Strokes block (U+31C0..U+31E5), or None")
      .def_readonly("compound", &TypicalStroke::compound, "False: a basic stroke, one piece; True: it turns")
      .def_property_readonly(
          "pieces",
          [](const TypicalStroke& t) {
            py::list out;
            for (const StrokePieceTemplate& piece : t.pieces) {
              out.append(py::cast(&piece, py::return_value_policy::reference));
            }
            return out;
          },
          "list of StrokePieceTemplate, the element template corner to corner")
      .def_readonly("default_attraction", &TypicalStroke::default_attraction,
                    "attraction factor of its feature points (dimensionless, paper eq. 8)")
      .def_readonly("corner_attraction", &TypicalStroke::corner_attraction,
                    "attraction factor at its corners (turning feature points)")
      .def("__repr__", [](const TypicalStroke& t) {
        return "<TypicalStroke " + std::to_string(t.id) + " " + std::string(t.acronym) + " " +
               std::string(t.name_zh) + ">";
      });

  py::tuple all(typical_strokes().size());
  for (std::size_t i = 0; i < typical_strokes().size(); ++i) {
    all[i] = py::cast(&typical_strokes()[i], py::return_value_policy::reference);
  }
  m.attr("TYPICAL_STROKES") = all;
  m.def(
      "typical_stroke",
      [](const Annotated<TypicalStrokeKeyTag>& key) { return &typical_stroke_by_key(key.object); },
      py::arg("key"), py::return_value_policy::reference,
      "The typical stroke with this ID (int, 1..39) or name (str): its acronym in any case ('HZG', 'hzg'), "
      "Chinese name ('横折钩') or CJK stroke character ('㇆'), as `calligraphy strokes` lists them and "
      "`calligraphy characters --typical` takes them (include/calligraphy/model/typical_strokes.hpp). Raises "
      "InvalidArgument (a ValueError) naming an unknown ID or name, TypeError for another type.");
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
          "(M, 2) float64, data units: the source median polyline (also from the bundled store and any "
          "format 1.1 corpus store; empty only for a character of a format 1.0 store)")
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
                              "A set of characters to load: the default set (every hanzi-writer-data "
                              "2.0.1 character, compiled into the module), a folder of "
                              "hanzi-writer-data files (fitted when loaded) or a corpus store of fitted "
                              "characters. Cheap to copy.")
      .def_static(
          "default", &CharacterSource::embedded,
          "The default set: the embedded subset of hanzi-writer-data 2.0.1 (fitted when loaded), then "
          "every other character of it from the corpus store compiled into the library (9,574 in "
          "all, fitted when the store was built, with their medians). Reads no file.")
      .def_static("embedded", &CharacterSource::embedded_only,
                  "The 58 characters embedded as hanzi-writer-data 2.0.1 JSON files (fitted when loaded), "
                  "without the bundled corpus store: a small set for quick examples and sweeps.")
      .def_static(
          "from_hanzi_writer",
          [](const PathLike& folder) {
            return CharacterSource::hanzi_writer_folder(
                convert_named<std::filesystem::path>(folder.object, "path"));
          },
          py::arg("path"),
          "A folder of hanzi-writer-data '<char>.json' files (fitted when loaded). Raises DataError (a "
          "RuntimeError) when it does not exist.")
      .def_static(
          "from_store",
          [](const PathLike& path) {
            return CharacterSource::store(convert_named<std::filesystem::path>(path.object, "path"));
          },
          py::arg("path"),
          "A binary corpus store of fitted characters (include/calligraphy/model/corpus_store.hpp, "
          "docs/corpus.md; made by `calligraphy corpus build`), read whole when opened: each character "
          "is decoded when loaded. Its Strokes have their data's medians (a store built with "
          "`--medians off` has none: Stroke.median is then (0, 2)). Raises DataError (a RuntimeError) "
          "naming the file and "
          "offset for a missing, truncated, corrupted or foreign file.")
      .def(
          "load",
          [](const CharacterSource& lib, const PyArgument<std::string>& c) {
            return lib.load(one_character(take(c, "char"), "char"));
          },
          py::arg("char"),
          "The Character for a one-character str. Raises CharacterNotFound (a KeyError) when absent, "
          "DataError for malformed data, InvalidArgument (a ValueError) unless exactly one character is "
          "given, TypeError for a non-str.")
      .def("__contains__",
           [](const CharacterSource& lib, const py::object& c) {
             if (!py::isinstance<py::str>(c)) return false;
             // A str UTF-8 cannot encode (a lone surrogate) names no character: not in any library.
             Py_ssize_t size = 0;
             const char* utf8 = PyUnicode_AsUTF8AndSize(c.ptr(), &size);
             if (utf8 == nullptr) {
               PyErr_Clear();
               return false;
             }
             const std::u32string chars = decode_utf8(std::string_view(utf8, static_cast<std::size_t>(size)));
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
      .def("__len__", [](const CharacterSource& lib) { return lib.characters().size(); })
      .def_property_readonly("description", &CharacterSource::description, "what the library reads")
      .def_property_readonly(
          "store_info",
          [](const CharacterSource& lib) -> Annotated<OptionalDictTag> {
            if (!lib.corpus_store()) return {py::none()};
            const CorpusStoreInfo& i = lib.corpus_store()->info();
            py::dict d;
            d["version"] = std::to_string(i.version_major) + "." + std::to_string(i.version_minor);
            d["character_count"] = i.character_count;
            d["steps_per_unit"] = i.steps_per_unit;
            d["fit_tolerance"] = i.fit_tolerance;
            d["max_quantisation_error"] = i.max_quantisation_error();
            d["file_bytes"] = i.file_bytes;
            d["medians"] = i.medians;
            d["outlines"] = i.outlines;
            return {d};
          },
          "For a corpus store, its header as a dict (version, character_count, steps_per_unit, "
          "fit_tolerance and max_quantisation_error in data units, file_bytes, medians and outlines: whether "
          "it holds the strokes' medians and their outlines, docs/corpus.md); else None.")
      .def("__repr__",
           [](const CharacterSource& lib) { return "<CharacterLibrary " + lib.description() + ">"; });
}

void check_placement(const Placement& p) {
  if (!p.origin_m.allFinite()) throw InvalidArgument("Placement.origin_m must be finite");
  if (!(p.metres_per_unit > 0.0) || !std::isfinite(p.metres_per_unit)) {
    throw InvalidArgument("Placement.metres_per_unit = " + std::to_string(p.metres_per_unit) +
                          " must be finite and > 0");
  }
}

// points (2,) or (N, 2) -> the same shape, each mapped by `f`.
template <typename F>
py::array_t<double> map_points(const ArrayLike& points, const char* name, F&& f) {
  const Vectors v = as_vectors(points.object, 2, name);
  return map_rows<2>(v, [&](py::ssize_t i) { return f(v.vec2(i)); });
}

py::array_t<double> box_to_array(const Eigen::AlignedBox2d& box) {
  auto out = new_array({2, 2});
  auto w = out.mutable_unchecked<2>();
  w(0, 0) = box.min().x();
  w(0, 1) = box.min().y();
  w(1, 0) = box.max().x();
  w(1, 1) = box.max().y();
  return read_only(out);
}

void bind_scene(py::module_& m) {
  ParameterClass<Placement>(
      m, "Placement",
      "Maps a character's data box (1024 units, y up) to metres on the paper: "
      "p_m = origin_m + metres_per_unit * p_data (include/calligraphy/model/scene.hpp).",
      check_placement)
      .field("origin_m", &Placement::origin_m, "where the data point (0, 0) lands [m].")
      .field("metres_per_unit", &Placement::metres_per_unit, "scale [m per data unit], > 0")
      .finish()
      .def(
          "to_paper",
          [](const Placement& p, const ArrayLike& points) {
            return map_points(points, "points", [&](const Vec2& q) { return p.to_paper(q); });
          },
          py::arg("points"),
          "Data units -> metres on the paper. points: (2,) or (N, 2) [data units]; returns the same shape, "
          "float64 [m]. Raises InvalidArgument (a ValueError) for another shape.")
      .def(
          "to_data",
          [](const Placement& p, const ArrayLike& points) {
            return map_points(points, "points_m", [&](const Vec2& q) { return p.to_data(q); });
          },
          py::arg("points_m"),
          "Metres on the paper -> data units, the inverse of to_paper. points_m: (2,) or (N, 2) [m]; returns "
          "the same shape, float64 [data units].");

  ParameterClass<SceneLayout>(
      m, "SceneLayout",
      "How a Scene lays characters out in a row on the paper plane z = paper_z_m, "
      "x right, y away from the writer (paper Figs. 5 and 30).",
      [](const SceneLayout& layout) { static_cast<void>(Scene::lay_out({}, layout)); })
      .field("character_size_m", &SceneLayout::character_size_m,
             "side of each character's data box on paper [m], in (0, 1]")
      .field("spacing_m", &SceneLayout::spacing_m, "centre-to-centre distance in the row [m], in (0, 1]")
      .field("centre_m", &SceneLayout::centre_m,
             "centre of the row on the paper [m], each coordinate in [-1, 1]")
      .field("paper_z_m", &SceneLayout::paper_z_m,
             "z0, height of the paper plane in device space [m], in [-1, 1]")
      .field("box_margin_m", &SceneLayout::box_margin_m,
             "bounding-box margin around the strokes (Fig. 5) [m], in [0, 0.1]")
      .field("start_radius_m", &SceneLayout::start_radius_m,
             "radius of the start-point neighbourhood (Fig. 5, Table 1) [m], in (0, 0.1]")
      .finish();

  py::class_<PlacedStroke>(m, "PlacedStroke", "A stroke placed on the paper, in metres.")
      .def_readonly("typical_id", &PlacedStroke::typical_id, "typical-stroke ID, 1..39")
      .def_property_readonly(
          "acronym", [](const PlacedStroke& s) { return std::string(typical_stroke(s.typical_id).acronym); },
          "the typical stroke's acronym")
      .def_readonly("elements", &PlacedStroke::elements, "list of StrokeElement, control points in metres")
      .def_property_readonly(
          "attraction_factors",
          [](const PlacedStroke& s) {
            auto out = new_array({static_cast<py::ssize_t>(s.attraction_factors.size())});
            for (std::size_t i = 0; i < s.attraction_factors.size(); ++i) {
              out.mutable_at(static_cast<py::ssize_t>(i)) = s.attraction_factors[i];
            }
            return read_only(out);
          },
          "(len(elements) + 1,) float64, dimensionless, one per feature point")
      .def_property_readonly(
          "median_m", [](const PlacedStroke& s) { return read_only(points_to_array(s.median_m)); },
          "(M, 2) float64, the source median [m] (empty for a corpus store's character)")
      .def_property_readonly(
          "centre_line_m",
          [](const PlacedStroke& s) { return read_only(points_to_array(s.centre_line.points_m)); },
          "(L, 2) float64, the centre line a person follows, along which progress and acceptance are "
          "measured (match_stroke): the source median, or the elements sampled densely without one [m]")
      .def_property_readonly(
          "corner_arcs_m",
          [](const PlacedStroke& s) {
            // The last element's end is the stroke's end, not a corner.
            const std::vector<double>& ends = s.centre_line.element_end_arc_m;
            const std::size_t corners = ends.empty() ? 0 : ends.size() - 1;
            auto out = new_array({static_cast<py::ssize_t>(corners)});
            for (std::size_t i = 0; i < corners; ++i) out.mutable_at(static_cast<py::ssize_t>(i)) = ends[i];
            return read_only(out);
          },
          "(len(elements) - 1,) float64, where each corner between elements lies along centre_line_m: arc "
          "length from its first point [m], non-decreasing")
      .def_property_readonly(
          "start_m", [](const PlacedStroke& s) { return read_only(to_array(s.start())); },
          "(2,) float64, start point [m]")
      .def_property_readonly(
          "end_m", [](const PlacedStroke& s) { return read_only(to_array(s.end())); },
          "(2,) float64, end point [m]")
      .def_property_readonly("length_m", &PlacedStroke::length_m, "arc length of its elements [m]")
      .def("__repr__", [](const PlacedStroke& s) {
        return "<PlacedStroke " + std::string(typical_stroke(s.typical_id).acronym) + ", " +
               std::to_string(s.elements.size()) + " element(s)>";
      });

  py::class_<PlacedCharacter>(m, "PlacedCharacter", "A character placed on the paper, in metres.")
      .def_property_readonly(
          "char", [](const PlacedCharacter& c) { return encode_utf8(c.code_point); }, "the character, a str")
      .def_property_readonly(
          "code_point", [](const PlacedCharacter& c) { return static_cast<std::uint32_t>(c.code_point); },
          "its Unicode code point")
      .def_readonly("placement", &PlacedCharacter::placement, "the Placement from data units to metres")
      .def_readonly("strokes", &PlacedCharacter::strokes, "list of PlacedStroke in stroke order")
      .def_property_readonly(
          "bounding_box_m", [](const PlacedCharacter& c) { return box_to_array(c.bounding_box); },
          "(2, 2) float64, [[x_min, y_min], [x_max, y_max]]: the strokes' box plus the margin [m]")
      .def("__repr__", [](const PlacedCharacter& c) {
        return "<PlacedCharacter " + encode_utf8(c.code_point) + ", " + std::to_string(c.strokes.size()) +
               " strokes>";
      });

  py::class_<Scene>(
      m, "Scene",
      "Characters placed in a row on the paper plane z = layout.paper_z_m, in metres (x right, y away from "
      "the writer), written left to right: the paper's character group (Fig. 30; "
      "include/calligraphy/model/scene.hpp).\n\n"
      "Each PlacedCharacter has a placement mapping its data box (1024 units, y up) to metres "
      "(Placement.to_paper / to_data on shape (2,) or (N, 2) arrays), its strokes with elements whose "
      "control points are in m, and bounding_box_m, shape (2, 2) [m]. strokes lists every PlacedStroke in "
      "writing order (median_m (M, 2) [m], start_m and end_m (2,) [m], length_m [m]). Immutable: a "
      "Renderer keeps a reference to it.")
      .def(py::init([](const Annotated<CharactersTag>& characters,
                       const std::optional<PyArgument<SceneLayout>>& layout,
                       const std::optional<PyArgument<CharacterSource>>& library) {
             const CharacterSource source = library ? take(*library, "library") : CharacterSource::embedded();
             const SceneLayout chosen = layout ? take(*layout, "layout") : SceneLayout{};
             return Scene::lay_out(characters_from(characters.object, source, "characters"), chosen);
           }),
           py::arg("characters"), py::arg("layout") = py::none(), py::arg("library") = py::none(),
           "characters: a str of one or more characters (loaded from `library`, default every character), a "
           "Character or a sequence of Characters. layout: a SceneLayout (default: 60 mm characters, 66 mm "
           "apart, centred at the origin, paper at z = 0). Raises CharacterNotFound (a KeyError), "
           "InvalidArgument (a ValueError), TypeError naming the argument.")
      .def_readonly("characters", &Scene::characters, "list of PlacedCharacter, left to right")
      .def_readonly("layout", &Scene::layout, "the SceneLayout it was laid out with")
      .def_property_readonly("stroke_count", &Scene::stroke_count, "strokes over all characters")
      .def_property_readonly(
          "strokes",
          [](const Scene& scene) {
            std::vector<PlacedStroke> out;
            for (const PlacedCharacter& c : scene.characters)
              out.insert(out.end(), c.strokes.begin(), c.strokes.end());
            return out;
          },
          "list of PlacedStroke over the scene in writing order: index i is TrialResult.stroke == i")
      .def("__repr__", [](const Scene& scene) {
        std::string chars;
        for (const PlacedCharacter& c : scene.characters) chars += encode_utf8(c.code_point);
        return "<Scene " + chars + ", " + std::to_string(scene.stroke_count()) + " strokes>";
      });
}

}  // namespace

void bind_model(py::module_& m) {
  bind_element(m);
  bind_typical_strokes(m);
  bind_character(m);
  bind_library(m);
  bind_scene(m);
}

namespace {

std::size_t index_below(const PyArgument<long long>& index, std::size_t count, const std::string& name,
                        const std::string& what) {
  // Any int, however large, is compared with the range (2**70 is as much out of it as 5).
  const py::handle value = index.object;
  const bool is_int = PyIndex_Check(value.ptr()) && !PyBool_Check(value.ptr());
  const py::object i = is_int ? py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr())) : py::object();
  if (is_int && !i) throw py::error_already_set();
  if (!is_int) static_cast<void>(take(index, name));  // the TypeError naming the argument
  if (i < py::int_(0) || i >= py::int_(count)) {
    throw py::index_error(name + ": " + short_repr(i) + " is not in 0.." +
                          std::to_string(static_cast<long long>(count) - 1) + " (" + what + " has " +
                          std::to_string(count) + ")");
  }
  return i.cast<std::size_t>();
}

}  // namespace

StrokeOfScene stroke_of_scene(const PyArgument<Scene>& scene_object,
                              const PyArgument<long long>& character_index,
                              const PyArgument<long long>& stroke_index) {
  if (!py::isinstance<Scene>(scene_object.object)) throw_type_error("scene", "Scene", scene_object.object);
  const Scene& scene = scene_object.object.cast<const Scene&>();
  const PlacedCharacter& character = scene.characters[index_below(
      character_index, scene.characters.size(), "character_index", "the scene's characters")];
  return {character,
          index_below(stroke_index, character.strokes.size(), "stroke_index", "the character's strokes")};
}

}  // namespace calligraphy::python
