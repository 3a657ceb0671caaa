// Kept apart from the rest: Xlib's headers define macros (None, Status, Bool) that clash with C++ code.
#include "trainer/x11_errors.hpp"

#include <X11/Xlib.h>

#include <atomic>

namespace calligraphy::trainer {
namespace {

std::atomic<bool> error_seen{false};

int record_error(Display* /*display*/, XErrorEvent* /*event*/) {
  error_seen.store(true, std::memory_order_relaxed);
  return 0;
}

}  // namespace

bool install_x11_error_handler() {
  XSetErrorHandler(record_error);
  return true;
}

bool x11_error_seen() noexcept { return error_seen.load(std::memory_order_relaxed); }

}  // namespace calligraphy::trainer
