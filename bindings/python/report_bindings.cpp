// report: the metrics of a trial as `calligraphy trial --json` writes them
// (include/calligraphy/report/trial_report.hpp).
#include "report_bindings.hpp"

#include <pybind11/pybind11.h>

#include "bindings.hpp"

namespace calligraphy::python {

py::dict trial_metrics(const cli::TrialDescription& d, const TrialResult& result) {
  const TrialMetrics& m = result.metrics;
  py::list per_stroke;
  for (const StrokeMetrics& s : m.per_stroke) {
    py::dict stroke;
    stroke["index"] = s.index + 1;
    stroke["typical_id"] = s.typical_id;
    stroke["mean_deviation_mm"] = s.mean_deviation_m * 1e3;
    stroke["max_deviation_mm"] = s.max_deviation_m * 1e3;
    stroke["time_s"] = s.time_s;
    stroke["completed"] = s.completed;
    stroke["attempts"] = s.attempts;
    per_stroke.append(stroke);
  }
  py::dict out;
  out["character"] = d.characters;
  out["guidance"] = d.guidance;
  out["writer"] = d.writer;
  out["seed"] = d.seed;
  out["rate_hz"] = d.rate_hz;
  out["device"] = d.device;
  out["aborted"] = result.aborted;
  out["abort_reason"] = result.abort_reason;
  out["strokes_total"] = m.strokes_total;
  out["strokes_completed"] = m.strokes_completed;
  out["completed_in_order"] = m.completed_in_order;
  out["time_s"] = m.time_s;
  out["mean_deviation_mm"] = m.mean_deviation_m * 1e3;
  out["max_deviation_mm"] = m.max_deviation_m * 1e3;
  out["max_force_n"] = m.max_force_n;
  out["max_force_step_n"] = m.max_force_step_n;
  out["state_transitions"] = m.state_transitions;
  out["per_stroke"] = per_stroke;
  return out;
}

void bind_report(py::module_& /*m*/) {}

}  // namespace calligraphy::python
