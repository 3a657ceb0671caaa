// report: the metrics of a trial from the same code as `calligraphy trial --json`
// (include/calligraphy/report/trial_report.hpp, trial_json), so Python and the CLI have one list of keys.
#include "report_bindings.hpp"

#include <pybind11/pybind11.h>

#include "bindings.hpp"

namespace calligraphy::python {

py::dict trial_metrics(const TrialDescription& description, const TrialResult& result) {
  const std::string text = trial_json(description, result);
  return py::module_::import("json").attr("loads")(py::str(text));
}

void bind_report(py::module_& /*m*/) {}

}  // namespace calligraphy::python
