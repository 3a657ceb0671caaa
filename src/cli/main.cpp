// The `calligraphy` program: guided writing trials on any device, models, the corpus store, benchmarks.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "cli/commands.hpp"

namespace {

constexpr const char* kUsage =
    "usage: calligraphy <command> [options]\n"
    "  trial CHARS [--device NAME] [--guidance on|off] [--writer novice|skilled] [--seed N]\n"
    "              [--data DIR] [--store FILE] [--json FILE] [--svg FILE] [--csv FILE]\n"
    "              [--pacing auto|lock-step|real-time] [--realtime enforce|ignore]\n"
    "                       run a guided writing trial at 1 kHz on a device (default: simulated)\n"
    "  model CHAR [--json] [--svg FILE] [--data DIR] [--store FILE]\n"
    "                       print the character's model (paper Table 3); --svg draws it (Fig. 13)\n"
    "  strokes [--markdown FILE] [--json]\n"
    "                       the table of the 39 typical strokes\n"
    "  corpus build [--data DIR] --out FILE [--tolerance UNITS] [--steps 1|2|4|8|16] [--threads N]\n"
    "                       model every character of hanzi-writer-data into a compact store\n"
    "  corpus stats FILE [--json]\n"
    "                       characters, strokes, elements, bytes, typical-stroke histogram, checksums\n"
    "  corpus fidelity [--data DIR] [--tolerances 2,5,10,20] [--markdown FILE]\n"
    "                       elements, bytes and deviation from the medians per fitting tolerance\n"
    "  corpus validate --data DIR --cnchar FILE [--markdown FILE] [--json] [--threads N] [--features FILE]\n"
    "                       per-stroke agreement of the classification with cnchar-order\n"
    "  devices              list the haptic devices found (simulated, Phantoms, OpenHaptics)\n"
    "  bench nearest [--json] [--markdown FILE] [--queries N] [--seed S]\n"
    "                       accuracy and speed of the nearest-point methods\n"
    "  bench jumps [--json] [--markdown FILE] [--seeds N] [--chars CHARS]\n"
    "                       foot-point jumps > 1 mm per stroke on real characters, by method\n"
    "  bench loop [--rate HZ] [--seconds S] [--realtime enforce|ignore|off] [--trial CHARS] [--json]\n"
    "                       period jitter and missed deadlines of the real-time servo loop\n"
    "  bench tick [--json] [--chars CHARS] [--passes N] [--rate HZ]\n"
    "                       cost of one servo tick (renderer and safety chain) over real trials\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace calligraphy::cli;
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  const Args args(argv + 2, argv + argc);
  // The library's log (device start-up, warnings) goes to stderr: stdout carries reports (--json) only.
  spdlog::set_default_logger(spdlog::stderr_color_mt("calligraphy"));
  try {
    if (command == "trial") return command_trial(args);
    if (command == "model") return command_model(args);
    if (command == "devices") return command_devices(args);
    if (command == "strokes") return command_strokes(args);
    if (command == "corpus" && !args.empty() && args[0] == "validate") return command_corpus_validate(args);
    if (command == "corpus") return command_corpus(args);
    if (command == "bench" && !args.empty() && args[0] == "nearest") return command_bench_nearest(args);
    if (command == "bench" && !args.empty() && args[0] == "jumps") return command_bench_jumps(args);
    if (command == "bench" && !args.empty() && args[0] == "loop") return command_bench_loop(args);
    if (command == "bench" && !args.empty() && args[0] == "tick") return command_bench_tick(args);
    std::fprintf(stderr, "calligraphy: error: unknown command '%s'\n%s", command.c_str(), kUsage);
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "calligraphy %s: error: %s\n", command.c_str(), e.what());
    return 2;
  } catch (const calligraphy::Error& e) {
    std::fprintf(stderr, "calligraphy %s: error: %s\n", command.c_str(), e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "calligraphy %s: internal error: %s\n", command.c_str(), e.what());
    return 3;
  }
}
