// The `calligraphy` program: runs guided writing trials on the simulated device and prints models.
#include <cstdio>
#include <exception>
#include <string>

#include "calligraphy/errors.hpp"
#include "cli/commands.hpp"

namespace {

constexpr const char* kUsage =
    "usage: calligraphy <command> [options]\n"
    "  trial CHARS [--guidance on|off] [--writer novice|skilled] [--seed N] [--data DIR]\n"
    "              [--json FILE] [--svg FILE] [--csv FILE]\n"
    "                       run a guided writing trial at 1 kHz on the simulated device\n"
    "  model CHAR [--json] [--data DIR]\n"
    "                       print the character's model (paper Table 3)\n"
    "  devices              list the haptic devices found (simulated, Phantoms, OpenHaptics)\n"
    "  bench nearest [--json] [--markdown FILE] [--queries N] [--seed S]\n"
    "                       accuracy and speed of the nearest-point methods\n"
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
  try {
    if (command == "trial") return command_trial(args);
    if (command == "model") return command_model(args);
    if (command == "devices") return command_devices(args);
    if (command == "bench" && !args.empty() && args[0] == "nearest") return command_bench_nearest(args);
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
