#pragma once
// The stop signals (SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGUSR2, SIGXCPU) as a request to stop (cli/signals.hpp
// records them); long runs (a study session) poll `stop_requested()` and end cleanly, keeping what they
// saved.
namespace calligraphy::cli {

/// Installs the handlers (once; later calls do nothing).
void install_stop_handlers();
/// True once a stop signal arrived.
bool stop_requested() noexcept;
/// The stop signal that arrived, or 0.
int stop_signal() noexcept;

}  // namespace calligraphy::cli
