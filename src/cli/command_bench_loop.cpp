// `calligraphy bench loop [--rate HZ] [--seconds S] [--realtime enforce|ignore|off] [--json] ...`: the
// real-time servo loop's period jitter, missed deadlines and callback time (eval/servo_loop_bench.hpp,
// docs/servo-loop.md).
#include <cstdio>
#include <memory>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/trial/options.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/signals.hpp"
#include "eval/servo_loop_bench.hpp"

namespace calligraphy::cli {
namespace {

struct LoopCommand {
  double rate_hz = ServoLoopOptions{}.rate_hz;
  double seconds = LoopBenchSettings{}.seconds;
  std::string realtime = "ignore";
  // The benchmark is a program that exists to run the loop: it asks for the real-time priority by default.
  std::int64_t priority = kDedicatedServoPriority;
  std::int64_t cpu = ServoLoopOptions{}.cpu;
  std::int64_t watchdog_periods = 0;
  std::string trial;
  LibraryOptions library;
  bool json = false;
};

int run_loop(const LoopCommand& command) {
  if (command.realtime == "enforce" && command.priority == 0) {
    throw UsageError("--priority: 0 (normal scheduling) cannot be enforced; give 1-99 or --realtime ignore");
  }
  LoopBenchSettings settings;
  settings.seconds = command.seconds;
  settings.realtime_mode = command.realtime;
  ServoLoopOptions& loop = settings.loop;
  loop.rate_hz = command.rate_hz;
  loop.realtime = command.realtime == "enforce" ? RealtimeMode::enforce : RealtimeMode::ignore;
  loop.priority = static_cast<int>(command.priority);
  loop.cpu = static_cast<int>(command.cpu);
  loop.lock_memory = true;
  if (command.realtime == "off") {  // a plain thread: the baseline without any realtime setting
    loop.priority = 0;
    loop.cpu = -1;
    loop.lock_memory = false;
  }
  // The stall bound in periods; off by default so that the whole run is measured (the worst lateness shows
  // in wake_latency_us_max and longest_stall).
  loop.stall_timeout_s = static_cast<double>(command.watchdog_periods) / loop.rate_hz;
  if (loop.stall_timeout_s > kMaxStallTimeoutS) {  // named by the options given, not by the loop's field
    throw UsageError("--watchdog-periods " + std::to_string(command.watchdog_periods) + " at --rate " +
                     shortest_decimal(command.rate_hz) + " is a stall of " +
                     shortest_decimal(loop.stall_timeout_s) + " s, more than the loop's bound of " +
                     shortest_decimal(kMaxStallTimeoutS) + " s");
  }
  if (!command.trial.empty()) {
    // The trial holds its trace in memory: named by the options given, not by the trial runner's field.
    if (exceeds_trial_ticks(command.seconds, command.rate_hz)) {
      throw UsageError("--seconds " + shortest_decimal(command.seconds) + " at --rate " +
                       shortest_decimal(command.rate_hz) +
                       " is more than 10^7 servo ticks, a trial's limit (--trial)");
    }
    settings.trial_characters = characters_from(command.trial, "--trial");
    const CharacterSource source(command.library);
    for (const char32_t c : settings.trial_characters) (void)source.load_named(c, "--trial");
  }
  // A stop signal ends the run early; its statistics are still printed.
  const StopSignals stop_signals;
  settings.should_stop = StopSignals::stop_requested();
  const LoopBenchResult result = run_loop_bench(library_from(command.library), settings);
  write_standard_output(command.json ? loop_bench_json(result, settings) : loop_bench_text(result, settings));
  if (const int signal = StopSignals::received()) {
    std::fprintf(stderr, "calligraphy bench loop: stopped by %s; the statistics cover the run until then\n",
                 signal_name(signal));
    return exit_status_after(signal);
  }
  return result.stats.fault ? 1 : 0;
}

}  // namespace

void add_bench_loop_command(CLI::App& bench, Commands& commands) {
  auto command = std::make_shared<LoopCommand>();
  CLI::App* app =
      commands.add(bench, "loop", "Period jitter and missed deadlines of the real-time servo loop",
                   [command] { return run_loop(*command); });
  add_number(*app, "--rate", command->rate_hz, "HZ", "servo rate [Hz], in " + servo_rate_range_text(true),
             "a rate in " + servo_rate_range_text(true),
             [](double hz) { return servo_rate_allowed(hz, true); });
  // A day at most, as a trial (kMaxTrialDurationS): the run's end is a clock reading that must not overflow.
  add_number(
      *app, "--seconds", command->seconds, "S",
      "how long to run; the trial's time limit [s, (0, 86400]]; with --trial, at most 10^7 ticks at --rate",
      "a number of seconds in (0, 86400]", [](double s) { return s > 0.0 && s <= kMaxTrialDurationS; });
  add_choice(
      *app, "--realtime", command->realtime, {"enforce", "ignore", "off"},
      "enforce: fail unless every realtime setting is obtained; ignore: try them; off: a plain thread");
  add_integer(*app, "--priority", command->priority, "P", "SCHED_FIFO priority of the loop thread; 0: none",
              0, 99);
  add_integer(*app, "--cpu", command->cpu, "N", "pin the loop thread to this CPU; -1: no pinning", -1, 1023);
  add_integer(
      *app, "--watchdog-periods", command->watchdog_periods, "N",
      "end the run when the device holds one force longer than N periods (at most 60 s of them at --rate); "
      "0: off",
      0, 1000000);
  add_text(*app, "--trial", command->trial, "CHARS", "run a real-time simulated trial of these characters",
           "none: the free loop, the simulated device held by a spring");
  add_library_options(*app, command->library, false);
  add_flag(*app, "--json", command->json, "print the statistics as JSON");
}

}  // namespace calligraphy::cli
