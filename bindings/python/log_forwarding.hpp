#pragma once
// The library's log, forwarded to Python's `logging` (logger "calligraphy").
//
// The C++ side never calls Python: the library's log handler (calligraphy/core/logging.hpp) queues each
// message (bounded; the oldest are dropped and counted when it is full), so the servo loop's log thread
// neither takes the GIL nor waits for Python. The
// queue is forwarded with the GIL held, at the end of each binding call that can log (`ForwardLog`, a
// pybind11 call guard) and by `calligraphy.flush_log()`.
#include <pybind11/pybind11.h>

namespace calligraphy::python {

namespace py = pybind11;

/// Installs the queueing handler as the library's log handler and binds set_log_level and flush_log.
void bind_logging(py::module_& m);

/// Forwards the queued messages to logging.getLogger("calligraphy"). Needs the GIL; never throws (an
/// error inside a logging handler is reported as unraisable).
void forward_queued_log() noexcept;

/// Call guard: forwards what the call logged when it returns (or raises).
struct ForwardLog {
  ForwardLog() = default;
  ForwardLog(const ForwardLog&) = delete;
  ForwardLog& operator=(const ForwardLog&) = delete;
  ~ForwardLog() { forward_queued_log(); }
};

}  // namespace calligraphy::python
