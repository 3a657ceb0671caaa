#pragma once
// SIGINT and SIGTERM as a request to stop: the handler only records the signal; long runs (a study
// session) poll `stop_requested()` and end cleanly, keeping what they saved.
namespace calligraphy::cli {

/// Installs the handlers (once; later calls do nothing).
void install_stop_handlers();
/// True once SIGINT or SIGTERM arrived.
bool stop_requested() noexcept;
/// The signal that arrived (SIGINT or SIGTERM), or 0.
int stop_signal() noexcept;

}  // namespace calligraphy::cli
