#pragma once
// The library's log (calligraphy/core/logging.hpp): the application's handler when it set one, else the
// spdlog logger it registered under kLoggerName, else spdlog's default logger. Off the servo path only (it
// may lock).
#include <spdlog/logger.h>

namespace calligraphy::detail {

[[nodiscard]] spdlog::logger& library_log();

}  // namespace calligraphy::detail
