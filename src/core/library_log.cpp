#include "core/library_log.hpp"

#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <utility>

#include "calligraphy/core/logging.hpp"

namespace calligraphy {
namespace {

spdlog::level::level_enum spdlog_level(LogLevel level) {
  static constexpr spdlog::level::level_enum kLevels[] = {
      spdlog::level::trace, spdlog::level::debug,    spdlog::level::info, spdlog::level::warn,
      spdlog::level::err,   spdlog::level::critical, spdlog::level::off};
  return kLevels[static_cast<int>(level)];
}

LogLevel log_level(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::trace:
      return LogLevel::trace;
    case spdlog::level::debug:
      return LogLevel::debug;
    case spdlog::level::info:
      return LogLevel::info;
    case spdlog::level::warn:
      return LogLevel::warning;
    case spdlog::level::err:
      return LogLevel::error;
    default:
      return LogLevel::critical;
  }
}

// Calls the application's handler. base_sink serialises the calls with its mutex; the handler is replaced
// under the same mutex, so a replaced handler is never called after set_log_handler returns.
class HandlerSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  LogHandler exchange(LogHandler handler) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::swap(handler_, handler);
    return handler;  // the previous one, destroyed by the caller outside the lock
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    if (!handler_) return;  // cleared while this message was on its way
    try {
      handler_(log_level(message.level), std::string_view(message.payload.data(), message.payload.size()));
    } catch (...) {  // the application's exception has nowhere to go from inside the library's log
    }
  }
  void flush_() override {}

 private:
  LogHandler handler_;
};

// The handler's logger: the library's own, never in spdlog's registry, so that nothing an application does to
// spdlog reaches it.
struct HandlerRoute {
  std::shared_ptr<HandlerSink> sink = std::make_shared<HandlerSink>();
  std::shared_ptr<spdlog::logger> logger = std::make_shared<spdlog::logger>(kLoggerName, sink);
  std::atomic<bool> active{false};
};

// Leaked on purpose: the servo loop's log thread or a static destructor may log until the process ends.
HandlerRoute& handler_route() {
  static HandlerRoute* const route = new HandlerRoute;
  return *route;
}

}  // namespace

namespace detail {

spdlog::logger& library_log() {
  HandlerRoute& route = handler_route();
  if (route.active.load(std::memory_order_acquire)) return *route.logger;
  // Looked up each time (a registry lookup, off the servo path): an application may register or replace the
  // logger of this name at any point. Without one, the default logger as it is now: a copy of its sinks
  // kept from an earlier moment could outlive them (a test's stream, say).
  if (std::shared_ptr<spdlog::logger> registered = spdlog::get(kLoggerName)) return *registered;
  return *spdlog::default_logger_raw();
}

}  // namespace detail

void set_log_handler(LogHandler handler) {
  HandlerRoute& route = handler_route();
  const bool active = static_cast<bool>(handler);
  // Installing: the handler is in place before the route is taken. Clearing: the route is left first. A
  // message logged by another thread during the switch may be dropped, none goes to a cleared handler.
  if (!active) route.active.store(false, std::memory_order_release);
  LogHandler previous = route.sink->exchange(std::move(handler));
  if (active) route.active.store(true, std::memory_order_release);
}

void set_log_level(LogLevel level) {
  handler_route().logger->set_level(spdlog_level(level));
  std::shared_ptr<spdlog::logger> logger = spdlog::get(kLoggerName);
  if (!logger) {  // the library's own, writing where the default logger writes now
    const std::shared_ptr<spdlog::logger> fallback = spdlog::default_logger();
    logger =
        std::make_shared<spdlog::logger>(kLoggerName, fallback->sinks().begin(), fallback->sinks().end());
    try {
      spdlog::register_logger(logger);
    } catch (const spdlog::spdlog_ex&) {  // another thread registered one first: use that one
      logger = spdlog::get(kLoggerName);
    }
  }
  logger->set_level(spdlog_level(level));
}

}  // namespace calligraphy
