#pragma once
/// \file logging.hpp
/// The library's log: device start-up, warnings such as a stiffness above a device's stable maximum, the
/// servo loop's late ticks (queued on the loop thread, written by a normal thread; never on the servo path).
///
/// The application owns it, without including spdlog:
///  - to take it, `set_log_handler([](LogLevel level, std::string_view message) { ... })`: every message at
///    or above the level goes to the handler instead of anywhere else; an empty handler gives it back;
///  - to silence it or change its level, `set_log_level(LogLevel::off)`.
///
/// Without a handler it goes through the spdlog logger named `kLoggerName` ("calligraphy"), so an application
/// that uses spdlog may also redirect it by registering a logger of that name with the sinks it wants
/// (`spdlog::register_logger(std::make_shared<spdlog::logger>("calligraphy", my_sink))`); the installed CMake
/// targets carry spdlog's compile definitions, so the application's spdlog calls reach the library's spdlog.
/// While neither is set, the library logs through spdlog's default logger (standard output, in colour, unless
/// the application replaced it). The command line writes it to standard error; the Python module forwards it
/// to `logging.getLogger("calligraphy")` through a handler.
#include <functional>
#include <string_view>

namespace calligraphy {

/// The name of the library's spdlog logger.
inline constexpr const char* kLoggerName = "calligraphy";

/// Levels of the library's log, spdlog's own (trace .. critical) without needing its headers.
enum class LogLevel { trace, debug, info, warning, error, critical, off };

/// Receives one message of the library's log: its level (never `off`) and its text, without time stamp or
/// level; `message` is valid during the call only.
using LogHandler = std::function<void(LogLevel level, std::string_view message)>;

/// Sends the library's log to `handler` from now on (it takes precedence over a spdlog logger named
/// `kLoggerName`); an empty handler restores the default (that logger, or spdlog's default logger). Calls to
/// the handler are serialised, from whichever thread logs (the caller's of a library function, or the servo
/// loop's log thread, never the servo thread); once `set_log_handler` returns, the previous handler is no
/// longer called. The handler must not call `set_log_handler`; an exception it throws is dropped. Messages
/// below the level of `set_log_level` (default info) are not even formatted. Thread-safe; not for the servo
/// path.
void set_log_handler(LogHandler handler);

/// Sets the level of the library's log, wherever it goes (a handler or spdlog): messages below it are not
/// even formatted; `LogLevel::off` silences it. When no spdlog logger named `kLoggerName` is registered yet,
/// registers one that writes to the default logger's sinks as they are now, so that the library's level is
/// its own. Thread-safe; not for the servo path.
void set_log_level(LogLevel level);

}  // namespace calligraphy
