#pragma once
// The library's spdlog logger (calligraphy/core/logging.hpp): the one the application registered under
// kLoggerName, or one the library registers on first use. Off the servo path only (it may lock).
#include <spdlog/logger.h>

namespace calligraphy::detail {

[[nodiscard]] spdlog::logger& library_log();

}  // namespace calligraphy::detail
