// Kept apart from the rest: Xlib's headers define macros (None, Status, Bool) that clash with C++ code.
#include "trainer/x11_errors.hpp"

#include <X11/Xlib.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <exception>
#include <utility>

namespace calligraphy::trainer {
namespace {

std::atomic<bool> error_seen{false};
std::atomic<bool> connection_lost{false};
std::function<void()> display_lost_ending;

int record_error(Display* /*display*/, XErrorEvent* /*event*/) {
  error_seen.store(true, std::memory_order_relaxed);
  return 0;
}

// Xlib exits when this returns: it ends the process itself, after the trainer kept its data. No Xlib call
// here (the connection is gone; Xlib is inside its own call on this thread).
[[noreturn]] void end_after_lost_display(Display* display) {
  connection_lost.store(true, std::memory_order_release);
  error_seen.store(true, std::memory_order_relaxed);
  const char* name = display != nullptr ? DisplayString(display) : nullptr;  // a field read, not a request
  std::fprintf(stderr,
               "calligraphy train: error: the display was lost (X connection to %s broken): ending the "
               "trial and keeping what was recorded\n",
               name != nullptr && name[0] != '\0' ? name : "the X server");
  std::fflush(stderr);
  if (display_lost_ending) {
    try {
      display_lost_ending();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "calligraphy train: error: after the lost display: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "calligraphy train: error: after the lost display: an unknown exception\n");
    }
  }
  std::fflush(stdout);
  std::fflush(stderr);
  // Not exit(): other threads (a session's, the servo loop's) may still hold locks the static
  // destructors take; what had to be kept is on disk already.
  _exit(kDisplayLostStatus);
}

int io_error(Display* display) { end_after_lost_display(display); }

}  // namespace

bool install_x11_error_handler() {
  XSetErrorHandler(record_error);
  XSetIOErrorHandler(io_error);
  return true;
}

bool x11_error_seen() noexcept { return error_seen.load(std::memory_order_relaxed); }

bool display_lost() noexcept { return connection_lost.load(std::memory_order_acquire); }

void set_display_lost_ending(std::function<void()> ending) { display_lost_ending = std::move(ending); }

}  // namespace calligraphy::trainer
