// `calligraphy bench loop --rate HZ --seconds S [--realtime enforce|ignore|off] [--json] ...`: runs the
// real-time servo loop against the simulated device and prints its period jitter, missed deadlines and
// callback time (docs/servo-loop.md).

#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"

namespace calligraphy::cli {

namespace {

constexpr const char* kUsage =
    "usage: calligraphy bench loop [--rate HZ] [--seconds S] [--realtime enforce|ignore|off] [--priority P]\n"
    "                              [--cpu N] [--watchdog-periods N] [--trial CHARS] [--data DIR] [--json]";

int integer_option(const Arguments& arguments, const std::string& name, int fallback, int minimum,
                   int maximum) {
  const double x = arguments.number_or(name, fallback);
  if (x != static_cast<double>(static_cast<int>(x)) || x < minimum || x > maximum) {
    throw UsageError("--" + name + " expects an integer in [" + std::to_string(minimum) + ", " +
                     std::to_string(maximum) + "]\n" + kUsage);
  }
  return static_cast<int>(x);
}

// The free loop: the simulated device with no hand, held near its start by a weak virtual spring, stepped
// by one period per tick inside the callback (lock-step physics paced by the loop).
ServoLoopStats run_free_loop(const ServoLoopOptions& options, double seconds) {
  SimulatedDevice device;
  device.open();
  const Vec3 home = SimulatedDeviceParameters{}.initial_position_m;
  const double period_s = 1.0 / options.rate_hz;
  ServoLoop loop(
      device,
      [&](const DeviceState& state, double) {
        const Vec3 force = -200.0 * (state.position_m - home) - 2.0 * state.velocity_m_s;  // [N/m], [N s/m]
        device.write_force(force);
        device.advance(period_s);
        return ServoCommand{force, false};
      },
      options);
  loop.start();
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (loop.running() && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  loop.stop();
  return loop.stats();
}

nlohmann::json stats_json(const ServoLoopStats& s) {
  nlohmann::json histogram = nlohmann::json::array();
  for (const HistogramBin& b : s.period_jitter_histogram) histogram.push_back({b.upper_us, b.count});
  return {{"rate_hz", s.rate_hz},
          {"ticks", s.ticks},
          {"missed_deadlines", s.missed_deadlines},
          {"skipped_periods", s.skipped_periods},
          {"forces_withheld", s.forces_withheld},
          {"longest_stall_ms", s.longest_stall_s * 1e3},
          {"deadline_reanchors", s.deadline_reanchors},
          {"period_jitter_us_p50", s.period_jitter_us_p50},
          {"period_jitter_us_p99", s.period_jitter_us_p99},
          {"period_jitter_us_max", s.period_jitter_us_max},
          {"wake_latency_us_max", s.wake_latency_us_max},
          {"callback_us_mean", s.callback_us_mean},
          {"callback_us_p99", s.callback_us_p99},
          {"callback_us_max", s.callback_us_max},
          {"realtime",
           {{"fifo_scheduling", s.realtime.fifo_scheduling},
            {"priority", s.realtime.priority},
            {"cpu", s.realtime.cpu},
            {"memory_locked", s.realtime.memory_locked},
            {"not_obtained", s.realtime.problems}}},
          {"fault", {{"kind", to_string(s.fault.kind)}, {"message", s.fault.message}}},
          {"period_jitter_histogram_us", histogram}};
}

void print_stats(const ServoLoopStats& s, double seconds) {
  std::printf("servo loop at %.0f Hz for %.1f s\n", s.rate_hz, seconds);
  std::printf("  ticks                  %llu\n", static_cast<unsigned long long>(s.ticks));
  std::printf("  missed_deadlines       %llu (skipped periods %llu)\n",
              static_cast<unsigned long long>(s.missed_deadlines),
              static_cast<unsigned long long>(s.skipped_periods));
  std::printf("  longest_stall_ms       %.3f (forces withheld %llu, deadlines re-anchored %llu)\n",
              s.longest_stall_s * 1e3, static_cast<unsigned long long>(s.forces_withheld),
              static_cast<unsigned long long>(s.deadline_reanchors));
  std::printf("  period_jitter_us_p50   %.1f\n", s.period_jitter_us_p50);
  std::printf("  period_jitter_us_p99   %.1f\n", s.period_jitter_us_p99);
  std::printf("  period_jitter_us_max   %.1f\n", s.period_jitter_us_max);
  std::printf("  wake_latency_us_max    %.1f\n", s.wake_latency_us_max);
  std::printf("  callback_us            mean %.2f, p99 %.2f, max %.1f\n", s.callback_us_mean,
              s.callback_us_p99, s.callback_us_max);
  std::printf("  realtime               SCHED_FIFO %s, CPU %s, memory locked %s\n",
              s.realtime.fifo_scheduling ? std::to_string(s.realtime.priority).c_str() : "no",
              s.realtime.cpu >= 0 ? std::to_string(s.realtime.cpu).c_str() : "not pinned",
              s.realtime.memory_locked ? "yes" : "no");
  if (!s.realtime.problems.empty()) std::printf("  not obtained           %s\n", s.realtime.problems.c_str());
  if (s.fault)
    std::printf("  fault                  %s: %s\n", to_string(s.fault.kind), s.fault.message.c_str());
}

}  // namespace

int command_bench_loop(const Args& args) {
  const Arguments arguments(
      args, {"rate", "seconds", "realtime", "priority", "cpu", "watchdog-periods", "trial", "data"},
      {"json"});
  if (arguments.positionals().size() != 1 || arguments.positionals()[0] != "loop") {
    throw UsageError(std::string("unexpected arguments\n") + kUsage);
  }
  ServoLoopOptions options;
  options.rate_hz = arguments.number_or("rate", 1000.0);
  const double seconds = arguments.number_or("seconds", 10.0);
  if (!(seconds > 0.0)) throw UsageError(std::string("--seconds expects a positive number\n") + kUsage);
  const std::string realtime = arguments.choice_or("realtime", {"enforce", "ignore", "off"}, "ignore");
  options.realtime = realtime == "enforce" ? RealtimeMode::enforce : RealtimeMode::ignore;
  options.priority = integer_option(arguments, "priority", 80, realtime == "enforce" ? 1 : 0, 99);
  options.cpu = integer_option(arguments, "cpu", -1, -1, 1023);
  options.lock_memory = true;
  if (realtime == "off") {  // a plain thread: the baseline without any realtime setting
    options.priority = 0;
    options.cpu = -1;
    options.lock_memory = false;
  }
  // The stall bound in periods; off by default so that the whole run is measured (the worst lateness
  // shows in wake_latency_us_max and longest_stall).
  options.stall_timeout_s = integer_option(arguments, "watchdog-periods", 0, 0, 1000000) / options.rate_hz;

  ServoLoopStats stats;
  nlohmann::json trial_json;
  if (const auto chars = arguments.option("trial")) {
    const CharacterLibrary library = library_from(arguments);
    std::vector<Character> characters;
    for (char32_t c : characters_from(*chars)) characters.push_back(library.load(c));
    const Scene scene = Scene::lay_out(characters);
    TrialOptions trial;
    trial.max_duration_s = seconds;
    trial.keep_trace = false;
    trial.pacing = TrialPacing::real_time;
    trial.rate_hz = options.rate_hz;
    trial.loop = options;
    const TrialResult result = run_simulated_trial(scene, trial);
    stats = result.loop.value_or(ServoLoopStats{});
    trial_json = {{"characters", *chars},
                  {"end", to_string(result.end)},
                  {"strokes_completed", result.metrics.strokes_completed},
                  {"strokes_total", result.metrics.strokes_total},
                  {"time_s", result.metrics.time_s}};
  } else {
    stats = run_free_loop(options, seconds);
  }

  if (arguments.flag("json")) {
    nlohmann::json out = stats_json(stats);
    out["seconds"] = seconds;
    out["realtime_mode"] = realtime;
    if (!trial_json.is_null()) out["trial"] = trial_json;
    std::cout << out.dump(2) << "\n";
  } else {
    print_stats(stats, seconds);
    if (!trial_json.is_null()) {
      std::printf("  trial                  %s: %s, %s of %s strokes in %.2f s\n",
                  trial_json["characters"].get<std::string>().c_str(),
                  trial_json["end"].get<std::string>().c_str(),
                  trial_json["strokes_completed"].dump().c_str(), trial_json["strokes_total"].dump().c_str(),
                  trial_json["time_s"].get<double>());
    }
  }
  return stats.fault ? 1 : 0;
}

}  // namespace calligraphy::cli
