#include "cli/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace calligraphy::cli {
namespace {

// Lock-free, so it may be written from a signal handler.
std::atomic<int> received{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void record_signal(int signal_number) { received.store(signal_number, std::memory_order_relaxed); }

}  // namespace

void install_stop_handlers() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = record_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return true;
  }();
  (void)installed;
}

bool stop_requested() noexcept { return received.load(std::memory_order_relaxed) != 0; }

int stop_signal() noexcept { return received.load(std::memory_order_relaxed); }

}  // namespace calligraphy::cli
