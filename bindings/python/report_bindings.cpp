// report: the metrics of a trial from the same code as `calligraphy trial --json`
// (include/calligraphy/report/trial_report.hpp, trial_json), so Python and the CLI have one list of keys;
// a teacher's recording for replay guidance (teacher_recording.hpp).
#include "report_bindings.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>

#include "arguments.hpp"
#include "bindings.hpp"
#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/report/trace_columns.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/study/cohort.hpp"
#include "calligraphy/study/curriculum.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "calligraphy/study/transfer_set.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "character_source.hpp"
#include "signal_poll.hpp"

namespace calligraphy::python {

py::dict metrics_from_json(const std::string& text) {
  return py::module_::import("calligraphy.metrics").attr("loads")(py::str(text));
}

py::dict trial_metrics(const TrialDescription& description, const TrialResult& result,
                       const WritingMetrics& writing) {
  const std::string text = trial_json(description, result, writing);
  return metrics_from_json(text);
}

void write_teacher_recording(const TeacherRecording& recording, const std::filesystem::path& path) {
  // An empty name is a mistake of the caller (a usage error), not a file that could not be written.
  if (path.empty()) throw InvalidArgument("path: empty; name the file to write the recording to");
  // Atomically: a reader (a running trainer, a protocol) never sees half a recording.
  write_file_atomically(path, teacher_recording_json(recording));
}

namespace {

// A column as a new numpy array (its values copied once, from the vector the reader filled).
template <typename T>
py::array_t<T> column_array(const std::vector<T>& values) {
  py::array_t<T> array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

}  // namespace

void bind_report(py::module_& m) {
  m.def(
      "metric_table",
      [] {
        py::list out;
        for (const MetricInfo& info : metric_table()) {
          py::dict row;
          row["name"] = std::string(info.name);
          row["kind"] = info.kind == MetricKind::count  ? "count"
                        : info.kind == MetricKind::flag ? "flag"
                                                        : "number";
          row["unit"] = std::string(info.unit);
          row["doc"] = std::string(info.doc);
          row["definition"] = std::string(info.definition);
          row["source"] = std::string(info.source);
          row["levels"] = metric_levels_text(info.levels);
          row["legacy_name"] = std::string(info.legacy_name);
          row["legacy_factor"] = info.legacy_factor;
          row["trials_column"] = info.trials_column;
          row["strokes_column"] = info.strokes_column;
          out.append(row);
        }
        return out;
      },
      R"(The one table of a trial's results (include/calligraphy/analysis/metric_table.hpp): a list of dicts
with ``name`` (its SI unit in it: "mean_deviation_m", "frechet_m", "total_time_s"; the key of every metrics
dict and DataFrame column), ``kind`` ("number", "count", "flag"), ``unit``, ``doc``, ``definition``,
``source``, ``levels`` ("scene, character, stroke", "run"), and ``legacy_name`` / ``legacy_factor``: the name
the metric had before (in mm: value x 1000), still readable from a metrics dict with a DeprecationWarning;
``trials_column`` / ``strokes_column``: its place among the metric columns of the study tables trials.csv
and strokes.csv (and ``calligraphy.study.load``'s DataFrames), counted from 1; 0 when it is not one.)");
  m.def(
      "trace_columns",
      [] {
        py::list out;
        for (const TraceColumnInfo& column : trace_columns()) {
          py::dict row;
          row["name"] = std::string(column.name);
          row["file_name"] = std::string(column.file_name);
          row["unit"] = std::string(column.unit);
          row["doc"] = std::string(column.doc);
          out.append(row);
        }
        return out;
      },
      R"(The one table of a pen trace's columns (include/calligraphy/report/trace_columns.hpp), in the CSV's
order: a list of dicts with ``name`` (its SI unit in it, as the library's DataFrames name it: "t_s", "x_m"),
``file_name`` (the CSV header's and the HDF5 trace's: "t", "x"), ``unit`` ("s", "m", "N" or "") and ``doc``.
``score`` reads a column by either name.)");
  m.def(
      "_read_trace_columns",
      [](const std::filesystem::path& path, std::uintmax_t max_file_bytes, const std::string& sha256) {
        TraceColumns c;
        {
          py::gil_scoped_release release;  // the file read and decoded in C++, beside other Python threads
          // Read once: the bytes parsed are the bytes hashed.
          const std::string bytes = read_trace_hdf5_bytes(path, max_file_bytes);
          c = parse_trace_hdf5(bytes, path.string());
          if (!sha256.empty()) {
            const std::string actual = sha256_hex(bytes);
            if (actual != sha256) {
              throw DataError(path.string() + ": SHA-256 " + actual +
                              ", but its record names a trace of SHA-256 " + sha256 +
                              " (files.trace_sha256): it is not this trial's trace");
            }
          }
        }
        py::dict columns;
        columns["t_s"] = column_array(c.time_s);
        columns["x_m"] = column_array(c.x_m);
        columns["y_m"] = column_array(c.y_m);
        columns["z_m"] = column_array(c.z_m);
        columns["fx_n"] = column_array(c.fx_n);
        columns["fy_n"] = column_array(c.fy_n);
        columns["fz_n"] = column_array(c.fz_n);
        columns["state"] = column_array(c.state);
        columns["stroke"] = column_array(c.stroke);
        columns["element"] = column_array(c.element);
        columns["attempt"] = column_array(c.attempt);
        columns["rewritten"] = column_array(c.rewritten);
        return columns;
      },
      py::arg("path"), py::arg("max_file_bytes"), py::arg("sha256") = std::string(),
      "Every column of a trial's HDF5 trace (read_trace_hdf5, include/calligraphy/report/trace_hdf5.hpp) as "
      "numpy arrays of N samples: t_s [s], x_m, y_m, z_m [m], fx_n, fy_n, fz_n [N] (float64), state (uint8: "
      "0 SS, 1 AS, 2 CS, 3 WS), stroke, element (uint32), attempt (int32), rewritten (uint8). Raises "
      "DataError "
      "naming the file for a damaged, cut, foreign or too large file, and, given `sha256` (its record's "
      "files.trace_sha256), for a file of another SHA-256 (another trial's trace), hashed from the bytes "
      "parsed: the file is read once. calligraphy.study reads traces with it.");
  m.def(
      "_study_tables_csv",
      [](const py::list& roots) {
        std::vector<std::filesystem::path> paths;
        for (const py::handle root : roots) {
          paths.push_back(
              convert_named<std::filesystem::path>(py::reinterpret_borrow<py::object>(root), "paths"));
        }
        StudyTables tables;
        {
          py::gil_scoped_release release;  // reading many records takes a while
          tables = read_study_tables(paths);
        }
        return py::make_tuple(trials_csv(tables), strokes_csv(tables));
      },
      py::arg("paths"),
      "The tidy tables of the session folders under `paths` as the CSV texts (trials, strokes) that "
      "`calligraphy report --csv` writes (read_study_tables, include/calligraphy/study/study_tables.hpp); "
      "calligraphy.study.load makes DataFrames of them. Raises DataError naming a damaged file.");
  m.attr("_MAX_COHORT_SUBJECTS") = kMaxCohortSubjects;
  m.def(
      "_simulate_cohort_csv",
      [](const std::string& protocol_path, const std::vector<std::pair<std::string, std::size_t>>& subjects,
         const std::string& profile, const std::string& learning, const CharacterSource& library,
         unsigned threads, bool individual_differences) {
        LoadedProtocol protocol = load_study_protocol(protocol_path);
        const auto load = [&library](char32_t c) { return library.load(c); };
        try {
          resolve_transfer_choices(protocol.protocol, load);
        } catch (const InvalidArgument& e) {
          throw InvalidArgument(protocol_path + ": " + e.what());
        }
        std::vector<SubjectAssignment> assigned;
        for (const auto& [id, number] : subjects) assigned.push_back({id, number});
        CohortSetup setup;
        setup.writer_profile = profile;
        try {
          setup.writer_learning = parse_enum<WriterLearning>(learning);
        } catch (const InvalidArgument& e) {
          throw InvalidArgument(std::string("CohortSetup.writer_learning: ") + e.what());
        }
        setup.individual_differences = individual_differences;
        setup.load_character = load;
        // Ctrl-C: the calling thread (one of the cohort's) runs Python's signal handlers every 50 ms; a
        // KeyboardInterrupt stops every trial at its next tick and is raised once every thread has stopped.
        SignalPoll poll;
        setup.should_stop = [&poll] { return poll.interrupted(); };
        StudyTables tables;
        try {
          py::gil_scoped_release release;  // minutes of simulation
          tables = simulate_cohort(protocol, assigned, setup, threads);
        } catch (...) {  // a trial stopped by the signal (StateError), or another thread's error meanwhile
          poll.raise_if_interrupted();
          throw;
        }
        return py::make_tuple(trials_csv(tables), strokes_csv(tables));
      },
      py::arg("protocol"), py::arg("subjects"), py::arg("profile"), py::arg("learning"), py::arg("library"),
      py::arg("threads"), py::arg("individual_differences") = true,
      "Simulated subjects [(id, number), ...] through every session of the protocol file in memory "
      "(simulate_cohort, include/calligraphy/study/cohort.hpp) on `threads` threads, each drawing its own "
      "traits from its id when `individual_differences` (sim/subject_traits.hpp): the CSV texts (trials, "
      "strokes) of their tidy tables. calligraphy.cohort.simulate wraps it.");
  m.def(
      "_propose_characters",
      [](const py::list& roots, const PyArgument<std::string>& subject_object,
         const PyArgument<std::string>& candidates_object, const PyArgument<long long>& count_object,
         const CharacterSource& library) {
        const std::string subject = take(subject_object, "subject");
        const std::string candidates = take(candidates_object, "candidates");
        // Refused as the command refuses --count and an empty --from.
        const long long count = take(count_object, "count");
        if (count < 1 || count > static_cast<long long>(kMaxProposedCharacters)) {
          throw InvalidArgument("count: " + std::to_string(count) + " is outside 1.." +
                                std::to_string(kMaxProposedCharacters));
        }
        if (candidates.empty()) throw InvalidArgument("candidates: give the characters to choose from");
        std::vector<std::filesystem::path> paths;
        for (const py::handle root : roots) {
          paths.push_back(
              convert_named<std::filesystem::path>(py::reinterpret_borrow<py::object>(root), "paths"));
        }
        const StudyTables tables = read_study_tables(paths);
        const auto typical_ids = [&library](char32_t c) {
          std::vector<int> ids;
          for (const Stroke& stroke : library.load(c).strokes) ids.push_back(stroke.typical_id);
          return ids;
        };
        py::list out;
        for (const ProposedCharacter& p :
             propose_characters(typical_stroke_record(tables, subject), written_characters(tables, subject),
                                decode_utf8(candidates), static_cast<std::size_t>(count), typical_ids)) {
          py::dict row;
          row["character"] = encode_utf8(p.character);
          row["new_strokes"] = p.new_strokes;
          row["weak_strokes"] = p.weak_strokes;
          out.append(row);
        }
        return out;
      },
      py::arg("paths"), py::arg("subject"), py::arg("candidates"), py::arg("count"), py::arg("library"),
      "The characters `subject` should practise next (propose_characters, include/calligraphy/study/"
      "curriculum.hpp): a list of dicts (character, new_strokes, weak_strokes: typical-stroke IDs). "
      "calligraphy.study.propose_characters wraps it.");
  py::class_<TeacherRecording>(
      m, "TeacherRecording",
      "A teacher's recorded trial for the replay guidance mode (include/calligraphy/report/"
      "teacher_recording.hpp; record and replay: Henmi & Yoshikawa 1998, Feygin, Keehner & Tendick 2002). "
      "Made by calligraphy.record_teacher(result) or `calligraphy trial --record FILE`; pass it as "
      "simulate_trial(..., teacher=recording). It guides only the characters it was recorded on, laid out "
      "the same way.")
      .def_readonly("characters", &TeacherRecording::characters, "the scene's characters, left to right")
      .def_readonly("writer", &TeacherRecording::writer,
                    "who wrote it, 'person' or the simulated writer's profile")
      .def_readonly("device", &TeacherRecording::device, "registry name of the device it was written on")
      .def_readonly("rate_hz", &TeacherRecording::rate_hz, "servo rate it was recorded at [Hz]")
      .def_readonly("library_version", &TeacherRecording::library_version,
                    "version of the library that recorded it (empty when unknown)")
      .def_readonly("samples", &TeacherRecording::samples,
                    "list of TeacherSample, the pen in the device frame [m] at times [s]")
      .def("to_json", &teacher_recording_json,
           "The recording as JSON text (format 'calligraphy-teacher-recording', version 1; numbers read "
           "back exactly).")
      .def(
          "save",
          [](const TeacherRecording& recording, const PathLike& path) {
            write_teacher_recording(recording, convert_named<std::filesystem::path>(path.object, "path"));
          },
          py::arg("path"),
          "Writes the JSON to `path` atomically (a temporary file renamed over it). Raises InvalidArgument "
          "(a ValueError) for an empty path, Error naming the path when it cannot be written.")
      .def_static(
          "load",
          [](const PathLike& path) {
            return read_teacher_recording(convert_named<std::filesystem::path>(path.object, "path"));
          },
          py::arg("path"),
          "Reads a recording file. Raises DataError naming the path (and the key, the sample index) for a "
          "missing, oversized or malformed file.")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source) {
            return parse_teacher_recording(text, source);
          },
          py::arg("text"), py::arg("source") = "<text>",
          "Parses the JSON format; `source` names the text in errors. Raises DataError naming the key.")
      .def("__len__", [](const TeacherRecording& r) { return r.samples.size(); })
      .def("__repr__", [](const TeacherRecording& r) {
        return "TeacherRecording(characters='" + r.characters + "', writer='" + r.writer + "', device='" +
               r.device + "', samples=" + std::to_string(r.samples.size()) + ")";
      });
}

}  // namespace calligraphy::python
