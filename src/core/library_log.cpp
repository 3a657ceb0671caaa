#include "core/library_log.hpp"

#include <spdlog/spdlog.h>

#include <memory>

#include "calligraphy/core/logging.hpp"

namespace calligraphy {
namespace detail {

spdlog::logger& library_log() {
  // Looked up each time (a registry lookup, off the servo path): an application may register or replace the
  // logger of this name at any point. Without one, the default logger as it is now: a copy of its sinks
  // kept from an earlier moment could outlive them (a test's stream, say).
  if (std::shared_ptr<spdlog::logger> registered = spdlog::get(kLoggerName)) return *registered;
  return *spdlog::default_logger_raw();
}

}  // namespace detail

void set_log_level(LogLevel level) {
  static constexpr spdlog::level::level_enum kLevels[] = {
      spdlog::level::trace, spdlog::level::debug,    spdlog::level::info, spdlog::level::warn,
      spdlog::level::err,   spdlog::level::critical, spdlog::level::off};
  std::shared_ptr<spdlog::logger> logger = spdlog::get(kLoggerName);
  if (!logger) {  // the library's own, writing where the default logger writes now
    const std::shared_ptr<spdlog::logger> fallback = spdlog::default_logger();
    logger = std::make_shared<spdlog::logger>(kLoggerName, fallback->sinks().begin(), fallback->sinks().end());
    try {
      spdlog::register_logger(logger);
    } catch (const spdlog::spdlog_ex&) {  // another thread registered one first: use that one
      logger = spdlog::get(kLoggerName);
    }
  }
  logger->set_level(kLevels[static_cast<int>(level)]);
}

}  // namespace calligraphy
