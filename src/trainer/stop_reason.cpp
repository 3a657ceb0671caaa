#include "trainer/stop_reason.hpp"

#include <string>

#include "calligraphy/core/stop_signals.hpp"
#include "trainer/x11_errors.hpp"

namespace calligraphy::trainer {

std::string stop_reason() {
  if (display_lost()) return "display_lost";
  if (StopSignals::received() != 0) return signal_name(StopSignals::received());
  return {};
}

}  // namespace calligraphy::trainer
