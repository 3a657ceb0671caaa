// The study commands' stop request, on the one signal handling of the command line (cli/signals.hpp).
#include "cli/interrupt.hpp"

#include "cli/signals.hpp"

namespace calligraphy::cli {

void install_stop_handlers() {
  // Lives until the process ends; the session commands install it once.
  static const StopSignals signals;
}

bool stop_requested() noexcept { return StopSignals::received() != 0; }

int stop_signal() noexcept { return StopSignals::received(); }

}  // namespace calligraphy::cli
