#include "calligraphy/core/stop_signals.hpp"

#include <atomic>
#include <csignal>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// Written by the handler, read by the command's thread: it must be lock-free to be async-signal-safe
// (C++20 [support.signal]).
std::atomic<int> received_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

// SIGUSR1 and SIGUSR2 (what a batch scheduler sends before it ends a job) and SIGXCPU (the soft CPU time
// limit reached, RLIMIT_CPU) would end the process before any file is written as well.
constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGUSR2, SIGXCPU};

extern "C" void record_stop_signal(int signal) {
  int none = 0;
  received_signal.compare_exchange_strong(none, signal);  // keep the first
}

struct SavedDispositions {
  struct sigaction stop[std::size(kStopSignals)];
  struct sigaction pipe;
  sigset_t mask;
};
SavedDispositions saved;
std::atomic<bool> installed_flag{false};

}  // namespace

StopSignals::StopSignals() {
  if (installed_flag.exchange(true)) throw StateError("stop signal handlers are installed already");
  received_signal.store(0);
  struct sigaction action {};
  action.sa_handler = record_stop_signal;
  sigemptyset(&action.sa_mask);
  for (int signal : kStopSignals) sigaddset(&action.sa_mask, signal);  // one handler at a time
  action.sa_flags = SA_RESTART;
  sigset_t caught;
  sigemptyset(&caught);
  for (std::size_t i = 0; i < std::size(kStopSignals); ++i) {
    sigaction(kStopSignals[i], nullptr, &saved.stop[i]);
    // An ignored SIGHUP was ignored on purpose (nohup: keep running when the terminal closes), so it stays
    // ignored, as do SIGUSR1, SIGUSR2 and SIGXCPU ignored by the parent. SIGINT and SIGTERM are caught
    // whatever they were: a background job's ignored SIGINT only keeps the terminal's Ctrl-C away, and a
    // stop asked for by kill must still end a trial cleanly.
    const bool always = kStopSignals[i] == SIGINT || kStopSignals[i] == SIGTERM;
    if (!always && saved.stop[i].sa_handler == SIG_IGN) continue;
    sigaction(kStopSignals[i], &action, nullptr);
    sigaddset(&caught, kStopSignals[i]);
  }
  // The same for a signal blocked when the process started (a parent's sigprocmask is inherited through
  // exec): it would stay pending and never stop anything. One sent before, pending, is delivered now.
  pthread_sigmask(SIG_UNBLOCK, &caught, &saved.mask);
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, &saved.pipe);
}

StopSignals::~StopSignals() {
  // After a stop the recording handler stays: a second Ctrl-C while the program shuts down (files being
  // closed, the sanitizers' checks at exit) must not end it another way than the first one asked for.
  if (received() == 0) {
    for (std::size_t i = 0; i < std::size(kStopSignals); ++i)
      sigaction(kStopSignals[i], &saved.stop[i], nullptr);
    pthread_sigmask(SIG_SETMASK, &saved.mask, nullptr);
  }
  sigaction(SIGPIPE, &saved.pipe, nullptr);
  installed_flag.store(false);
}

std::span<const int> stop_signal_numbers() noexcept { return kStopSignals; }

bool StopSignals::installed() noexcept { return installed_flag.load(); }

int StopSignals::received() noexcept { return received_signal.load(std::memory_order_relaxed); }

std::function<bool()> StopSignals::stop_requested() {
  return [] { return received() != 0; };
}

const char* signal_name(int signal) noexcept {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGUSR1:
      return "SIGUSR1";
    case SIGUSR2:
      return "SIGUSR2";
    case SIGXCPU:
      return "SIGXCPU";
    default:
      return "a signal";
  }
}

}  // namespace calligraphy
