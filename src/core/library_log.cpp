#include "core/library_log.hpp"

#include <spdlog/spdlog.h>

#include <memory>

#include "calligraphy/core/logging.hpp"

namespace calligraphy {
namespace detail {

spdlog::logger& library_log() {
  // Looked up each time (a registry lookup, off the servo path): an application may register or replace the
  // logger of this name at any point.
  if (std::shared_ptr<spdlog::logger> registered = spdlog::get(kLoggerName)) return *registered;
  const std::shared_ptr<spdlog::logger> fallback = spdlog::default_logger();
  auto created = std::make_shared<spdlog::logger>(kLoggerName, fallback->sinks().begin(), fallback->sinks().end());
  created->set_level(fallback->level());
  try {
    spdlog::register_logger(created);
  } catch (const spdlog::spdlog_ex&) {  // another thread registered one first: use that one
    if (std::shared_ptr<spdlog::logger> registered = spdlog::get(kLoggerName)) return *registered;
  }
  // The registry keeps the logger for the life of the process unless the application drops it.
  return *spdlog::get(kLoggerName);
}

}  // namespace detail

void set_log_level(LogLevel level) {
  static constexpr spdlog::level::level_enum kLevels[] = {
      spdlog::level::trace, spdlog::level::debug,    spdlog::level::info, spdlog::level::warn,
      spdlog::level::err,   spdlog::level::critical, spdlog::level::off};
  detail::library_log().set_level(kLevels[static_cast<int>(level)]);
}

}  // namespace calligraphy
