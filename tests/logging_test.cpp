// The log the application owns (calligraphy/core/logging.hpp): a handler takes every message at the library's
// level, with its level and without spdlog; an empty handler gives the log back to spdlog; set_log_level
// filters and silences it. And how the library's messages print a rate.
#include "calligraphy/core/logging.hpp"

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <catch2/catch.hpp>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/library_log.hpp"
#include "core/rate_text.hpp"

using namespace calligraphy;

TEST_CASE("The library's log goes to the application's handler, at the library's level, and back to spdlog",
          "[log]") {
  // spdlog's side: a logger named "calligraphy" writing to a stream, which the handler must take precedence
  // over.
  std::ostringstream spdlog_stream;
  spdlog::drop(kLoggerName);
  spdlog::register_logger(std::make_shared<spdlog::logger>(
      kLoggerName, std::make_shared<spdlog::sinks::ostream_sink_mt>(spdlog_stream)));

  std::vector<std::pair<LogLevel, std::string>> received;
  set_log_handler([&](LogLevel level, std::string_view message) { received.emplace_back(level, message); });
  detail::library_log().warn("stiffness {} N/m above {} N/m", 5000, 1000);
  detail::library_log().debug("below the default level");
  set_log_level(LogLevel::error);
  detail::library_log().warn("filtered");
  detail::library_log().error("kept");
  set_log_level(LogLevel::off);
  detail::library_log().critical("silenced");
  set_log_level(LogLevel::info);
  set_log_handler([](LogLevel, std::string_view) { throw std::runtime_error("the application's bug"); });
  CHECK_NOTHROW(detail::library_log().warn("dropped by a throwing handler"));
  set_log_handler({});
  detail::library_log().warn("back to spdlog");
  spdlog::drop(kLoggerName);  // the stream ends with this test

  REQUIRE(received.size() == 2);
  CHECK(received[0] ==
        std::pair<LogLevel, std::string>{LogLevel::warning, "stiffness 5000 N/m above 1000 N/m"});
  CHECK(received[1] == std::pair<LogLevel, std::string>{LogLevel::error, "kept"});
  const std::string through_spdlog = spdlog_stream.str();
  CHECK(through_spdlog.find("back to spdlog") != std::string::npos);
  CHECK(through_spdlog.find("stiffness") == std::string::npos);  // nothing the handler had went to spdlog too
}

TEST_CASE("Rates in messages read as numbers of Hz", "[log][rate]") {
  CHECK(detail::rate_text(500.0) == "500 Hz");
  CHECK(detail::rate_text(1000.0) == "1000 Hz");
  CHECK(detail::rate_text(99.96) == "99.96 Hz");  // a refused rate shown as given, not rounded into range
  CHECK(detail::measured_rate_text(678.33333) == "678.3 Hz");
  CHECK(detail::measured_rate_text(999.97) == "1000 Hz");
  CHECK(detail::measured_rate_text(2000.0 / 3.0) == "666.7 Hz");
}
