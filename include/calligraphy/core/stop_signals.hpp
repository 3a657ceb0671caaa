#pragma once
// Stopping a trial, a session or a servo-loop benchmark cleanly when the person at the terminal or the
// system asks: SIGINT (Ctrl-C), SIGTERM (kill, a service manager), SIGHUP (the terminal closed), SIGUSR1 and
// SIGUSR2 (a batch scheduler's warning before it ends a job) and SIGXCPU (the soft CPU time limit) only
// record the request; the program polls it (TrialOptions::should_stop), stops at the next tick with zero
// force and forces disabled, writes what was recorded and exits with 128 + the signal's number (130, 143,
// 129, 138, 140, 152), the shell's convention for a command ended by a signal. A recording that cannot be
// repeated is thus never lost to a signal: the default action would end the process before any file is
// written. One implementation for the command line, the trainer window and applications that run trials.
#include <functional>
#include <span>

namespace calligraphy {

/// While it lives, the stop signals (`stop_signal_numbers`) are caught (sigaction with SA_RESTART, so that
/// interrupted reads and writes resume) and unblocked in the thread that made it, except a SIGHUP, SIGUSR1,
/// SIGUSR2 or SIGXCPU that was ignored when it was made (`nohup`: the command goes on when its terminal
/// closes), and SIGPIPE is ignored (a closed
/// standard output becomes a write error that is reported, not a death before the files are written). Every
/// later stop signal is recorded as well, so a second Ctrl-C while the files are written cannot lose them;
/// SIGKILL and SIGQUIT still end the process. The previous dispositions and signal mask are restored on
/// destruction, except after a stop was received: then further stop signals stay caught (and change nothing)
/// until the process exits, so that a second Ctrl-C during the shutdown cannot change how it ends. One at a
/// time per process: the constructor throws StateError when another one lives (see `installed`).
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// True while a StopSignals lives (then a second one cannot be made; poll `received` instead).
  [[nodiscard]] static bool installed() noexcept;
  /// The first stop signal received since the handlers were installed, or 0. Lock-free; any thread.
  [[nodiscard]] static int received() noexcept;
  /// `received() != 0`, as a function for TrialOptions::should_stop.
  [[nodiscard]] static std::function<bool()> stop_requested();
};

/// The stop signals StopSignals catches: SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGUSR2, SIGXCPU.
[[nodiscard]] std::span<const int> stop_signal_numbers() noexcept;

/// "SIGINT", "SIGTERM", "SIGHUP", "SIGUSR1", "SIGUSR2", "SIGXCPU", or "a signal" for any other.
[[nodiscard]] const char* signal_name(int signal) noexcept;

/// The exit status of a command ended by `signal`: 128 + its number.
[[nodiscard]] constexpr int exit_status_after(int signal) noexcept { return 128 + signal; }

}  // namespace calligraphy
