#pragma once
/// \file logging.hpp
/// The library's log: device start-up, warnings such as a stiffness above a device's stable maximum, the
/// servo loop's late ticks (queued on the loop thread, written by a normal thread; never on the servo path).
///
/// It goes through the spdlog logger named `kLoggerName` ("calligraphy"), so an application configures it as
/// any spdlog logger:
///  - to redirect it, register a logger of that name with the sinks it wants before the library logs
///    (`spdlog::register_logger(std::make_shared<spdlog::logger>("calligraphy", my_sink))`);
///  - to silence it or change its level, `set_log_level(LogLevel::off)` (or
///    `spdlog::get("calligraphy")->set_level(...)`).
/// While no logger of that name is registered, the library logs through spdlog's default logger (standard
/// output, in colour, unless the application replaced it). The command line writes it to standard error; the
/// Python module forwards it to `logging.getLogger("calligraphy")`.
namespace calligraphy {

/// The name of the library's spdlog logger.
inline constexpr const char* kLoggerName = "calligraphy";

/// Levels of the library's log, spdlog's own (trace .. critical) without needing its headers.
enum class LogLevel { trace, debug, info, warning, error, critical, off };

/// Sets the level of the library's logger: messages below it are not even formatted; `LogLevel::off` silences
/// it. When none is registered yet, registers one named `kLoggerName` that writes to the default logger's
/// sinks as they are now, so that the library's level is its own. Thread-safe; not for the servo path.
void set_log_level(LogLevel level);

}  // namespace calligraphy
