#include "log_forwarding.hpp"

#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <cctype>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "arguments.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy::python {
namespace {

struct QueuedMessage {
  int python_level = 0;
  std::string text;
};

// Enough for every message of a long session between two Python calls; the library logs at start-up
// and on faults, never per tick.
constexpr std::size_t kMaxQueued = 10000;

int python_level(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::trace:
      return 5;
    case spdlog::level::debug:
      return 10;
    case spdlog::level::info:
      return 20;
    case spdlog::level::warn:
      return 30;
    case spdlog::level::err:
      return 40;
    default:
      return 50;
  }
}

class QueueSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  // Takes what was queued and the number dropped since the last call.
  std::deque<QueuedMessage> take(std::size_t& dropped) {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    std::deque<QueuedMessage> out;
    out.swap(queue_);
    dropped = dropped_;
    dropped_ = 0;
    return out;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    QueuedMessage queued{python_level(message.level),
                         std::string(message.payload.data(), message.payload.size())};
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.size() >= kMaxQueued) {
      queue_.pop_front();
      ++dropped_;
    }
    queue_.push_back(std::move(queued));
  }
  void flush_() override {}

 private:
  std::mutex queue_mutex_;  // separate from the sink's own, so `take` never waits on formatting
  std::deque<QueuedMessage> queue_;
  std::size_t dropped_ = 0;
};

// Leaked on purpose: spdlog's registry may log through it until the process ends, after Python is gone.
const std::shared_ptr<QueueSink>& sink() {
  static const auto* instance = new std::shared_ptr<QueueSink>(std::make_shared<QueueSink>());
  return *instance;
}

spdlog::level::level_enum spdlog_level(int python_level) {
  if (python_level <= 5) return spdlog::level::trace;
  if (python_level <= 10) return spdlog::level::debug;
  if (python_level <= 20) return spdlog::level::info;
  if (python_level <= 30) return spdlog::level::warn;
  if (python_level <= 40) return spdlog::level::err;
  if (python_level <= 50) return spdlog::level::critical;
  return spdlog::level::off;
}

struct LogLevelTag {
  static constexpr auto name = py::detail::const_name("Union[int, str]");
};

void set_log_level(const Annotated<LogLevelTag>& level) {
  const py::object logging = py::module_::import("logging");
  int value = 0;
  if (py::isinstance<py::str>(level.object)) {
    std::string name = level.object.cast<std::string>();
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    const py::object number = logging.attr("getLevelName")(name);  // "DEBUG" -> 10; unknown -> "Level X"
    if (!py::isinstance<py::int_>(number)) {
      throw InvalidArgument(
          "level: expected a logging level name (DEBUG, INFO, WARNING, ERROR, CRITICAL), got '" +
          level.object.cast<std::string>() + "'");
    }
    value = number.cast<int>();
  } else if (PyLong_Check(level.object.ptr()) && !PyBool_Check(level.object.ptr())) {
    value = convert_named<int>(level.object, "level");
    if (value < 0) throw_int_out_of_range("level", level.object, false, 31);  // logging levels are >= 0
  } else {
    throw_type_error("level", "a logging level (int) or its name (str)", level.object);
  }
  spdlog::set_level(spdlog_level(value));
  logging.attr("getLogger")("calligraphy").attr("setLevel")(value);
}

}  // namespace

void forward_queued_log() noexcept {
  std::size_t dropped = 0;
  std::deque<QueuedMessage> messages = sink()->take(dropped);
  if (messages.empty() && dropped == 0) return;
  try {
    const py::object logger = py::module_::import("logging").attr("getLogger")("calligraphy");
    if (dropped > 0) {
      logger.attr("warning")("%d log messages of the C++ library were dropped (queue full)", dropped);
    }
    for (const QueuedMessage& m : messages) logger.attr("log")(m.python_level, "%s", m.text);
  } catch (py::error_already_set& e) {
    e.discard_as_unraisable("calligraphy: forwarding the C++ log to Python's logging");
  } catch (...) {  // nothing may escape a destructor
  }
}

void bind_logging(py::module_& m) {
  auto logger = std::make_shared<spdlog::logger>("calligraphy", sink());
  logger->set_level(spdlog::level::info);
  spdlog::set_default_logger(logger);

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
