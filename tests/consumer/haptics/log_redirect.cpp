// The application owns the library's log, built against the installed `calligraphy::haptics` alone (the
// consumer finds no spdlog package: it includes spdlog's headers from the system, as a user's program would).
// A real library warning (a paper stiffness above the device's stable maximum, logged when a Renderer is
// made):
//  0. by default it reaches standard output (which shows that the capture below sees the library's output);
//  1. set_log_handler takes it, and nothing reaches standard output;
//  2. without a handler, a spdlog logger named "calligraphy" registered by the application takes it (the
//     application's spdlog and the library's share one registry);
//  3. set_log_level(LogLevel::off) silences it.
// Exits 1, naming the step, when one does not hold.
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <calligraphy/core/logging.hpp>
#include <calligraphy/devices/simulated_device.hpp>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/render/renderer.hpp>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace {

// What the library writes to standard output (file descriptor 1) while `action` runs.
template <typename Action>
std::string standard_output_of(Action action) {
  std::fflush(stdout);
  std::FILE* capture = std::tmpfile();
  const int saved = dup(1);
  if (capture == nullptr || saved < 0 || dup2(fileno(capture), 1) < 0) {
    std::fprintf(stderr, "log_redirect: cannot capture standard output\n");
    std::exit(2);
  }
  action();
  std::fflush(stdout);
  dup2(saved, 1);
  close(saved);
  std::string text;
  std::rewind(capture);
  for (int c = std::fgetc(capture); c != EOF; c = std::fgetc(capture)) text.push_back(static_cast<char>(c));
  std::fclose(capture);
  return text;
}

// Makes a renderer whose paper is stiffer than the device's stable maximum: the library warns, once.
void warn_once() {
  using namespace calligraphy;
  static const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  ForceLawParameters force;
  force.paper_stiffness_n_per_m = 5000.0;
  const Renderer renderer(scene, force, simulated_phantom_desktop_info());
}

bool mentions_warning(std::string_view text) { return text.find("stable maximum") != std::string_view::npos; }

int failed(const char* step, const std::string& detail) {
  std::fprintf(stderr, "log_redirect: %s (%s)\n", step, detail.c_str());
  return 1;
}

}  // namespace

int main() {
  using namespace calligraphy;

  const std::string by_default = standard_output_of(warn_once);
  if (!mentions_warning(by_default))
    return failed("0: by default the warning goes to standard output", by_default);

  std::vector<std::pair<LogLevel, std::string>> handled;
  set_log_handler(
      [&handled](LogLevel level, std::string_view message) { handled.emplace_back(level, message); });
  const std::string with_handler = standard_output_of(warn_once);
  set_log_handler({});
  if (handled.empty() || handled[0].first != LogLevel::warning || !mentions_warning(handled[0].second)) {
    return failed("1: the handler receives the warning", std::to_string(handled.size()) + " messages");
  }
  if (!with_handler.empty()) return failed("1: nothing reaches standard output", with_handler);

  std::ostringstream application_sink;
  spdlog::register_logger(std::make_shared<spdlog::logger>(
      kLoggerName, std::make_shared<spdlog::sinks::ostream_sink_mt>(application_sink)));
  const std::string with_spdlog_logger = standard_output_of(warn_once);
  const std::string redirected = application_sink.str();
  if (!mentions_warning(redirected))
    return failed("2: the registered spdlog logger receives the warning", redirected);
  if (!with_spdlog_logger.empty()) return failed("2: nothing reaches standard output", with_spdlog_logger);

  set_log_level(LogLevel::off);
  const std::string silenced = standard_output_of(warn_once);
  const bool sink_unchanged = application_sink.str() == redirected;
  spdlog::drop(kLoggerName);  // the stream ends with main
  if (!sink_unchanged) return failed("3: LogLevel::off silences the log", application_sink.str());
  if (!silenced.empty()) return failed("3: nothing reaches standard output", silenced);

  std::printf(
      "the library's log: to standard output by default, to a handler, to a spdlog logger, silenced\n");
  return 0;
}
