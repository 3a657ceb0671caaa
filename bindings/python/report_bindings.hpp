#pragma once
// The report functions other binding files use.
#include <pybind11/pybind11.h>

#include <filesystem>
#include <string>

#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/trial/teacher_recording.hpp"

namespace calligraphy::python {

namespace py = pybind11;

/// A metrics record's JSON text as Python dicts (`calligraphy.metrics.loads`): every object a
/// `calligraphy.metrics.Metrics`, which still reads a metric's old millimetre name with a DeprecationWarning.
py::dict metrics_from_json(const std::string& text);

/// The trial's metrics as a dict with the keys of `calligraphy trial --json`.
py::dict trial_metrics(const TrialDescription& description, const TrialResult& result,
                       const WritingMetrics& writing);

/// Writes `recording` as JSON to `path` atomically (write_file_atomically).
void write_teacher_recording(const TeacherRecording& recording, const std::filesystem::path& path);

}  // namespace calligraphy::python
