#pragma once
// SIGINT, SIGTERM and SIGHUP as a request to stop (cli/signals.hpp records them); long runs (a study
// session) poll `stop_requested()` and end cleanly, keeping what they saved.
namespace calligraphy::cli {

/// Installs the handlers (once; later calls do nothing).
void install_stop_handlers();
/// True once a stop signal arrived.
bool stop_requested() noexcept;
/// The signal that arrived (SIGINT, SIGTERM or SIGHUP), or 0.
int stop_signal() noexcept;

}  // namespace calligraphy::cli
