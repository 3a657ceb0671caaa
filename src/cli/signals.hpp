#pragma once
// The command line's stop signals: the one implementation the trainer window shares (core/stop_signals.hpp),
// under the names the commands use.
#include "calligraphy/core/stop_signals.hpp"

namespace calligraphy::cli {

using calligraphy::exit_status_after;
using calligraphy::signal_name;
using calligraphy::StopSignals;

}  // namespace calligraphy::cli
