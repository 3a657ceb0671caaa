// score: a pen trace from any source (a CSV file, or columns from numpy or pandas) scored against a
// character, as `calligraphy score` does (analysis/score.hpp, report/score_report.hpp), with the same JSON
// keys.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arguments.hpp"
#include "bindings.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/score_report.hpp"
#include "calligraphy/report/trace_columns.hpp"
#include "character_source.hpp"
#include "model_bindings.hpp"
#include "numpy_arrays.hpp"
#include "report_bindings.hpp"

namespace calligraphy::python {
namespace {

using Column = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Column `key` of a mapping (dict of arrays, pandas DataFrame) as a 1-D float64 array.
Column column(const py::object& columns, const char* key) {
  Column values;
  try {
    const py::object given = columns[py::str(key)];
    // forcecast takes a complex column's real part (numpy's ComplexWarning aside) and parses text ("1" in a
    // pandas column of str): refused instead, as neither is a column of real numbers.
    check_real_numbers(given, std::string("trace: column '") + key + "'");
    values = Column::ensure(given);
  } catch (const py::error_already_set&) {
    values = Column();
  }
  if (!values || values.ndim() != 1) {
    throw InvalidArgument(std::string("trace: column '") + key + "' is not a 1-D array of numbers");
  }
  return values;
}

bool has_column(const py::object& columns, const char* key) {
  return py::bool_(columns.attr("__contains__")(py::str(key)));
}

// The key under which `columns` holds the trace column whose file name is `file_name` ("t"): its name with
// its unit ("t_s", as the library's DataFrames name it: trace_columns.hpp) or its file name; "time_s", the
// name TrialResult.to_dataframe gave the time before, is read for one more version with a note. Empty when
// none is there.
// A column given under both names ("x" and "x_m") is refused, as a CSV header naming it twice is
// (pen_trace_csv.hpp): a reader would otherwise take one of the two without a word.
std::string column_key(const py::object& columns, const char* file_name) {
  const std::optional<TraceColumnInfo> info = trace_column(file_name);
  const bool by_name = info && has_column(columns, std::string(info->name).c_str());
  const bool by_file_name = has_column(columns, file_name);
  if (by_name && by_file_name) {
    throw InvalidArgument(std::string("trace: column '") + file_name + "' is given twice, as '" + file_name +
                          "' and as '" + std::string(info->name) + "'");
  }
  if (by_name) return std::string(info->name);
  if (by_file_name) return file_name;
  if (std::string_view(file_name) == "t" && has_column(columns, "time_s")) {
    if (PyErr_WarnEx(PyExc_DeprecationWarning,
                     "trace: column 'time_s' is named 't_s' now (read for one more version)", 1) != 0)
      throw py::error_already_set();
    return "time_s";
  }
  return {};
}

// The samples of a mapping with columns t, x, y and pen (1/0) or z [m] (pen_trace_csv.hpp's columns), each by
// its file name or its name with its unit (t_s, x_m, y_m, z_m).
std::vector<PenSample> samples_from_columns(const py::object& columns, TraceUnits units,
                                            const Placement& placement, double contact_threshold_m,
                                            double paper_z_m) {
  // A numpy array has both, but `"t" in array` compares its elements with "t": it is no mapping of columns
  // (a structured array's fields included); nor is a list or tuple (of paths, of arrays), which has both too.
  if (!py::hasattr(columns, "__getitem__") || !py::hasattr(columns, "__contains__") ||
      py::isinstance<py::array>(columns) || py::isinstance<py::list>(columns) ||
      py::isinstance<py::tuple>(columns)) {
    throw py::type_error(
        "trace: expected a CSV file's path or a mapping of columns (a dict of arrays, a "
        "pandas DataFrame) with t, x, y and pen or z (or t_s, x_m, y_m, z_m)");
  }
  std::string keys[3];
  for (int i = 0; i < 3; ++i) {
    const char* file_name = std::array{"t", "x", "y"}[static_cast<std::size_t>(i)];
    keys[i] = column_key(columns, file_name);
    if (keys[i].empty()) {
      throw InvalidArgument(std::string("trace: no column '") + file_name + "' or '" +
                            std::string(trace_column(file_name)->name) + "'");
    }
  }
  const bool pen_column = has_column(columns, "pen");
  const std::string z_key = column_key(columns, "z");
  if (!pen_column && z_key.empty()) throw InvalidArgument("trace: no column 'pen' or 'z' (or 'z_m')");
  // As a CSV header with both is refused (pen_trace_csv.cpp): which of two contacts to believe is not
  // guessed.
  if (pen_column && !z_key.empty()) {
    throw InvalidArgument("trace: both a 'pen' and a '" + z_key +
                          "' column; give one, so that pen contact is unambiguous");
  }
  const Column t = column(columns, keys[0].c_str()), x = column(columns, keys[1].c_str()),
               y = column(columns, keys[2].c_str());
  const Column contact = column(columns, pen_column ? "pen" : z_key.c_str());
  const py::ssize_t n = t.shape(0);
  if (x.shape(0) != n || y.shape(0) != n || contact.shape(0) != n) {
    std::string lengths;
    const std::array<std::pair<const std::string*, py::ssize_t>, 4> given{
        {{&keys[0], n}, {&keys[1], x.shape(0)}, {&keys[2], y.shape(0)}, {nullptr, contact.shape(0)}}};
    for (const auto& [key, length] : given) {
      if (!lengths.empty()) lengths += ", ";
      lengths.append("'").append(key ? *key : (pen_column ? std::string("pen") : z_key)).append("' ");
      lengths.append(std::to_string(length));
    }
    throw InvalidArgument("trace: the columns have different lengths (" + lengths + ")");
  }
  // The limit a CSV or HDF5 trace has (docs/cli.md, "Pen traces: format and limits"), so that the same
  // samples are scored or refused alike from a file and from columns.
  if (const std::size_t limit = PenTraceCsvOptions{}.max_samples; static_cast<std::size_t>(n) > limit) {
    throw InvalidArgument("trace: " + std::to_string(n) + " samples, more than " + std::to_string(limit) +
                          " samples, the limit of one trace");
  }
  std::vector<PenSample> samples(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    const double c = contact.at(i);
    if (pen_column && c != 0.0 && c != 1.0) {
      throw InvalidArgument("trace: sample " + std::to_string(i) + ": pen is " + std::to_string(c) +
                            ", expected 1 (on paper) or 0 (lifted)");
    }
    if (!pen_column && !std::isfinite(c)) {
      throw InvalidArgument("trace: sample " + std::to_string(i) + ": z is not a finite number");
    }
    // Named by its column, as a CSV trace's field is named (the segmentation would only say "a sample").
    const std::array<std::pair<const std::string*, double>, 3> values{
        {{&keys[0], t.at(i)}, {&keys[1], x.at(i)}, {&keys[2], y.at(i)}}};
    for (const auto& [key, value] : values) {
      if (!std::isfinite(value)) {
        throw InvalidArgument("trace: sample " + std::to_string(i) + ": column '" + *key +
                              "' is not a finite number");
      }
    }
    const Vec2 position(x.at(i), y.at(i));
    PenSample& sample = samples[static_cast<std::size_t>(i)];
    sample.time_s = t.at(i);
    sample.position_m = units == TraceUnits::data ? placement.to_paper(position) : position;
    sample.pen_down = pen_column ? c == 1.0 : c - paper_z_m <= contact_threshold_m;
  }
  return samples;
}

py::dict score_py(const py::object& trace, const py::object& character,
                  const PyArgument<std::string>& units_arg,
                  const std::optional<PyArgument<CharacterSource>>& library,
                  const PyArgument<double>& contact_threshold_arg,
                  const std::optional<PyArgument<StrokeAcceptance>>& acceptance,
                  const PyArgument<double>& start_radius_arg) {
  // Each argument converted by name: a value of another type is a TypeError naming it, a lone surrogate an
  // InvalidArgument (arguments.hpp), never pybind11's "incompatible function arguments".
  const std::string units_name = take(units_arg, "units");
  const double contact_threshold_m = take(contact_threshold_arg, "contact_threshold_m");
  const double start_radius_m = take(start_radius_arg, "start_radius_m");
  // The spellings this function documents and the command line's --units takes: "m" or "data".
  if (units_name != "m" && units_name != "data")
    throw InvalidArgument("units: '" + units_name +
                          "' is neither 'm' (metres) nor 'data' (the 1024-unit box)");
  const TraceUnits units = parse_trace_units(units_name == "m" ? "metres" : units_name);
  if (!std::isfinite(start_radius_m) || !(start_radius_m > 0.0))
    throw InvalidArgument("start_radius_m: " + shortest_decimal(start_radius_m) + " m is not finite and > 0");
  // A Scene (the one a trial was written on, TrialResult.scene) is scored as it was laid out: its row, size,
  // start radius and paper height, which a `z` column is measured from, as the trial measured it.
  Scene scene;
  if (py::isinstance<Scene>(character)) {
    scene = character.cast<Scene>();
    if (scene.characters.empty()) throw InvalidArgument("character: the scene has no character");
    if (units == TraceUnits::data && scene.characters.size() != 1) {
      throw InvalidArgument(
          "units: 'data' takes one character (data units are one character's); the scene has " +
          std::to_string(scene.characters.size()));
    }
  } else {
    // One or more characters, a row laid out as simulate_trial lays it out, as `score --character CHARS`.
    const CharacterSource source = library ? take(*library, "library") : CharacterSource::embedded();
    const std::vector<Character> models = characters_from(character, source, "character");
    if (units == TraceUnits::data && models.size() != 1) {
      throw InvalidArgument(
          "units: 'data' takes one character (data units are one character's); character has " +
          std::to_string(models.size()));
    }
    SceneLayout layout;
    layout.start_radius_m = start_radius_m;
    scene = Scene::lay_out(models, layout);
  }
  const PlacedCharacter& placed = scene.characters.front();
  std::string characters;
  for (const PlacedCharacter& c : scene.characters) characters += encode_utf8(c.code_point);

  std::vector<PenSample> samples;
  std::string trace_name = "<columns>";
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(trace) || py::isinstance<py::bytes>(trace) ||
      py::isinstance(trace, os.attr("PathLike"))) {
    // A path as str, bytes or path-like object (the file system's encoding, as open() reads it); a NUL in it
    // is an InvalidArgument naming `trace`, never a shorter name read.
    trace_name = convert_named<std::filesystem::path>(trace, "trace").string();
    PenTraceCsvOptions options;
    options.units = units;
    options.contact_threshold_m = contact_threshold_m;
    options.paper_z_m = scene.layout.paper_z_m;
    samples = read_pen_trace_csv(trace_name, placed.placement, options);
  } else {
    if (!std::isfinite(contact_threshold_m))
      throw InvalidArgument("contact_threshold_m: not a finite number");
    samples =
        samples_from_columns(trace, units, placed.placement, contact_threshold_m, scene.layout.paper_z_m);
  }
  ScoreOptions options;
  if (acceptance) options.acceptance = take(*acceptance, "acceptance");
  const WritingMetrics metrics = writing_metrics(scene, samples, options);
  const ScoreDescription description{characters, trace_name, units == TraceUnits::data ? "data" : "m",
                                     samples.size()};
  return metrics_from_json(score_json(description, metrics));
}

}  // namespace

void bind_score(py::module_& m) {
  m.def(
      "score", &score_py, py::arg("trace"), py::arg("character"), py::arg("units") = "m",
      py::arg("library") = py::none(),
      py::arg("contact_threshold_m") = PenTraceCsvOptions{}.contact_threshold_m,
      py::arg("acceptance") = py::none(), py::arg("start_radius_m") = ScoreOptions{}.start_radius_m,
      R"(Scores a pen trace from any source against a character, as `calligraphy score` does (analysis/score.hpp;
metrics defined in docs/metrics.md): strokes segmented at pen lifts and matched to the reference strokes
with the stroke matcher the renderer uses (match_stroke, docs/stroke-acceptance.md), so order and
direction errors are found, and each segment gets the verdict the renderer would have given it in turn.

trace: the path of a CSV file (header t, x, y and pen or z; other columns ignored: `trial --csv` output
       reads as it is), or a mapping of columns (a dict of 1-D arrays, a pandas DataFrame) with `t` [s],
       `x`, `y` and `pen` (1 on paper, 0 lifted) or `z` [m] (on paper when z <= contact_threshold_m), not both.
character: a str of one or more characters (loaded from `library`, default every character), a Character
           or a sequence of them, laid out as `simulate_trial` places them (a row, as `calligraphy score
           --character CHARS` places it); or a Scene (a row of characters, or a trial's
           `TrialResult.scene`), scored as it is laid out: its placement, its start radius (not
           `start_radius_m`) and its paper height, which `z` is measured from (on paper when
           z - paper_z_m <= contact_threshold_m), so that a trial's trace scores as the trial did.
units: 'm' (metres on the paper plane of that placement) or 'data' (the 1024-unit box, y up; one
       character only).
acceptance: a StrokeAcceptance (default: the C++ defaults, the renderer's).
start_radius_m: radius of the start neighbourhood a segment must enter a stroke in [m], > 0 (default the
                scene's, 0.005).
Returns a dict with the keys of `calligraphy score --json` (order_errors, backwards_strokes,
mean_deviation_m, frechet_m, dtw_m [m], strokes_accepted, strokes_assisted, refusals: {reason: count},
..., and per character under per_character its per_stroke (assisted: credited after
acceptance.assist_after_misses refusals while due, as the renderer credits it) and segments: one dict per
pen-down segment with begin/end sample indices (0-based, end exclusive), matched_stroke and a verdict dict
(accepted, refusal name, expected_stroke, matched_stroke, assists_due) or None); stroke numbers are 0-based, as per_stroke's index and
Scene(...).characters[0].strokes; a value that does not exist is None.
Raises DataError (file unreadable, bad row: naming line and column), InvalidArgument (a bad column,
sample or option, naming it), CharacterNotFound, TypeError.)");
}

}  // namespace calligraphy::python
