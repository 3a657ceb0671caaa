#pragma once
// Why the trainer's window ends a trial early, as a trial's record and a session's log name it.
#include <string>

namespace calligraphy::trainer {

/// "display_lost" after a lost X connection, the stop signal's name ("SIGINT", "SIGTERM", "SIGHUP"), or
/// empty (a key, the window closed).
[[nodiscard]] std::string stop_reason();

}  // namespace calligraphy::trainer
