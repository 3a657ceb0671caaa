#pragma once
// The parts of the extension module `calligraphy._calligraphy`, one per library module, called in this
// order by module.cpp (later parts use the classes of earlier ones).
#include <pybind11/pybind11.h>

namespace calligraphy::python {

namespace py = pybind11;

void bind_core(py::module_& m);             // exceptions, __version__, DeviceState, DeviceInfo
void bind_logging(py::module_& m);          // spdlog -> Python logging (log_forwarding.hpp)
void bind_model(py::module_& m);            // elements, characters, libraries, typical strokes, scenes
void bind_collision(py::module_& m);        // nearest_point
void bind_render(py::module_& m);           // force law, interaction states, renderer
void bind_sim(py::module_& m);              // simulated device and writer, device registry
void bind_writer_learning(py::module_& m);  // writer logs, profiles by name, learning across repetitions
void bind_report(py::module_& m);           // trial reports (JSON metrics), teacher recordings
void bind_trial(py::module_& m);            // simulated trials
void bind_score(py::module_& m);            // scoring of any pen trace

}  // namespace calligraphy::python

namespace calligraphy {
class DeviceRegistry;
}  // namespace calligraphy

namespace calligraphy::python {

/// The module's device registry: the standard backends and the Phantom over USB (sim_bindings.cpp).
[[nodiscard]] const DeviceRegistry& python_device_registry();

}  // namespace calligraphy::python
