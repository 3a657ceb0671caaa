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
/// When the application registered none, the library registers one on its first message that writes to the
/// sinks of spdlog's default logger at that moment (standard output, in colour, unless the application
/// replaced the default logger). The command line writes it to standard error; the Python module forwards it
/// to `logging.getLogger("calligraphy")`.
namespace calligraphy {

/// The name of the library's spdlog logger.
inline constexpr const char* kLoggerName = "calligraphy";

/// Levels of the library's log, spdlog's own (trace .. critical) without needing its headers.
enum class LogLevel { trace, debug, info, warning, error, critical, off };

/// Sets the level of the library's logger (registering it first, as above, when it is not there yet): messages
/// below it are not even formatted. `LogLevel::off` silences it. Thread-safe; not for the servo path.
void set_log_level(LogLevel level);

}  // namespace calligraphy
