#include "log_forwarding.hpp"

#include <cctype>
#include <deque>
#include <mutex>
#include <string>
#include <string_view>

#include "arguments.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/logging.hpp"

namespace calligraphy::python {
namespace {

struct QueuedMessage {
  int python_level = 0;
  std::string text;
};

// Enough for every message of a long session between two Python calls; the library logs at start-up
// and on faults, never per tick.
constexpr std::size_t kMaxQueued = 10000;

int python_level(LogLevel level) {
  switch (level) {
    case LogLevel::trace:
      return 5;
    case LogLevel::debug:
      return 10;
    case LogLevel::info:
      return 20;
    case LogLevel::warning:
      return 30;
    case LogLevel::error:
      return 40;
    default:
      return 50;
  }
}

// What the library's log handler fills and `forward_queued_log` empties.
class LogQueue {
 public:
  void push(LogLevel level, std::string_view text) {
    QueuedMessage queued{python_level(level), std::string(text)};
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.size() >= kMaxQueued) {
      queue_.pop_front();
      ++dropped_;
    }
    queue_.push_back(std::move(queued));
  }
  // Takes what was queued and the number dropped since the last call.
  std::deque<QueuedMessage> take(std::size_t& dropped) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::deque<QueuedMessage> out;
    out.swap(queue_);
    dropped = dropped_;
    dropped_ = 0;
    return out;
  }

 private:
  std::mutex mutex_;
  std::deque<QueuedMessage> queue_;
  std::size_t dropped_ = 0;
};

// Leaked on purpose: the library may log through the handler until the process ends, after Python is gone.
LogQueue& log_queue() {
  static LogQueue* const instance = new LogQueue;
  return *instance;
}

LogLevel library_level(int python_level) {
  if (python_level <= 5) return LogLevel::trace;
  if (python_level <= 10) return LogLevel::debug;
  if (python_level <= 20) return LogLevel::info;
  if (python_level <= 30) return LogLevel::warning;
  if (python_level <= 40) return LogLevel::error;
  if (python_level <= 50) return LogLevel::critical;
  return LogLevel::off;
}

struct LogLevelTag {
  static constexpr auto name = py::detail::const_name("Union[int, str]");
};

void set_log_level(const Annotated<LogLevelTag>& level) {
  const py::object logging = py::module_::import("logging");
  int value = 0;
  if (py::isinstance<py::str>(level.object)) {
    const std::string given = convert_named<std::string>(level.object, "level");  // a lone surrogate: a value
    std::string name = given;
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    const py::object number = logging.attr("getLevelName")(name);  // "DEBUG" -> 10; unknown -> "Level X"
    if (!py::isinstance<py::int_>(number)) {
      throw InvalidArgument(
          "level: expected a logging level name (DEBUG, INFO, WARNING, ERROR, CRITICAL), got '" + given +
          "'");
    }
    value = number.cast<int>();
  } else if (PyLong_Check(level.object.ptr()) && !PyBool_Check(level.object.ptr())) {
    value = convert_named<int>(level.object, "level");
    if (value < 0) throw_int_out_of_range("level", level.object, false, 31);  // logging levels are >= 0
  } else {
    throw_type_error("level", "a logging level (int) or its name (str)", level.object);
  }
  calligraphy::set_log_level(library_level(value));
  logging.attr("getLogger")("calligraphy").attr("setLevel")(value);
}

}  // namespace

void forward_queued_log() noexcept {
  std::size_t dropped = 0;
  std::deque<QueuedMessage> messages = log_queue().take(dropped);
  if (messages.empty() && dropped == 0) return;
  // Each message on its own: a handler or filter that raises for one is reported as Python reports an
  // exception it cannot raise (sys.unraisablehook), and the messages after it are still forwarded.
  const auto forward = [](const auto& send) noexcept {
    try {
      send();
    } catch (py::error_already_set& e) {
      e.discard_as_unraisable("calligraphy: forwarding the C++ log to Python's logging");
    } catch (...) {  // nothing may escape a destructor
    }
  };
  py::object logger;
  forward([&] { logger = py::module_::import("logging").attr("getLogger")("calligraphy"); });
  if (!logger) return;
  if (dropped > 0) {
    forward([&] {
      logger.attr("warning")("%d log messages of the C++ library were dropped (queue full)", dropped);
    });
  }
  for (const QueuedMessage& m : messages) forward([&] { logger.attr("log")(m.python_level, "%s", m.text); });
}

void bind_logging(py::module_& m) {
  // The library's own handler: the process's spdlog (its default logger, other loggers) is left alone.
  set_log_handler([](LogLevel level, std::string_view message) { log_queue().push(level, message); });

  m.def("set_log_level", &set_log_level, py::arg("level"),
        "Sets the level of the library's log: a logging level (logging.DEBUG, 20, ...) or its name "
        "('debug', 'WARNING', ...). Applies to the C++ side (messages below it are not even formatted) "
        "and to logging.getLogger('calligraphy'). The C++ log reaches Python's logging when a call that "
        "can log returns, or at flush_log(). Raises InvalidArgument (a ValueError) for an unknown name, "
        "TypeError for another type.");
  m.def("flush_log", &forward_queued_log,
        "Forwards the C++ log messages queued so far (e.g. from another thread) to "
        "logging.getLogger('calligraphy') now.");
}

}  // namespace calligraphy::python
