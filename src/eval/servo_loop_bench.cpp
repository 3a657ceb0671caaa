#include "eval/servo_loop_bench.hpp"

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"
#include "report/appendf.hpp"

namespace calligraphy::cli {
namespace {

// The free loop: stepped by one period per tick inside the callback (lock-step physics paced by the loop).
ServoLoopStats run_free_loop(const ServoLoopOptions& options, double seconds,
                             const std::function<bool()>& should_stop) {
  SimulatedDevice device;
  device.open();
  const Vec3 home = SimulatedDeviceParameters{}.initial_position_m;
  const double period_s = 1.0 / options.rate_hz;
  ServoLoop loop(
      device,
      [&](const DeviceState& state, double) {
        const Vec3 force = -200.0 * (state.position_m - home) - 2.0 * state.velocity_m_s;  // [N/m], [N s/m]
        // Written here too, so that the step below acts under it (an open simulated device has no faults).
        if (device.write_force(force) != DeviceFault::none) return ServoCommand{Vec3::Zero(), true};
        device.advance(period_s);
        return ServoCommand{force, false};
      },
      options);
  loop.start();
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (loop.running() && std::chrono::steady_clock::now() < until && !(should_stop && should_stop())) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  loop.stop();
  return loop.stats();
}

}  // namespace

LoopBenchResult run_loop_bench(const CharacterLibrary& library, const LoopBenchSettings& settings) {
  LoopBenchResult result;
  if (settings.trial_characters.empty()) {
    result.stats = run_free_loop(settings.loop, settings.seconds, settings.should_stop);
    return result;
  }
  std::vector<Character> characters;
  for (char32_t c : settings.trial_characters) characters.push_back(library.load(c));
  const Scene scene = Scene::lay_out(characters);
  TrialOptions trial;
  trial.max_duration_s = settings.seconds;
  trial.keep_trace = false;
  trial.pacing = TrialPacing::real_time;
  trial.rate_hz = settings.loop.rate_hz;
  trial.loop = settings.loop;
  trial.should_stop = settings.should_stop;
  const TrialResult run = run_simulated_trial(scene, trial);
  result.stats = run.loop.value_or(ServoLoopStats{});
  LoopBenchTrial summary;
  for (char32_t c : settings.trial_characters) summary.characters += encode_utf8(c);
  summary.end = to_string(run.end);
  summary.strokes_completed = run.metrics.strokes_completed;
  summary.strokes_total = run.metrics.strokes_total;
  summary.time_s = run.metrics.time_s;
  result.trial = summary;
  return result;
}

std::string loop_bench_json(const LoopBenchResult& result, const LoopBenchSettings& settings) {
  const ServoLoopStats& s = result.stats;
  nlohmann::json histogram = nlohmann::json::array();
  for (const HistogramBin& b : s.period_jitter_histogram) histogram.push_back({b.upper_us, b.count});
  nlohmann::json out = {{"rate_hz", s.rate_hz},
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
                        {"fault",
                         {{"kind", to_string(s.fault.kind)},
                          {"device", device_fault_name(s.fault.device)},
                          {"message", s.fault.message}}},
                        {"period_jitter_histogram_us", histogram}};
  out["seconds"] = settings.seconds;
  out["realtime_mode"] = settings.realtime_mode;
  if (result.trial) {
    const LoopBenchTrial& t = *result.trial;
    out["trial"] = {{"characters", t.characters},
                    {"end", t.end},
                    {"strokes_completed", t.strokes_completed},
                    {"strokes_total", t.strokes_total},
                    {"time_s", t.time_s}};
  }
  return out.dump(2) + "\n";
}

std::string loop_bench_text(const LoopBenchResult& result, const LoopBenchSettings& settings) {
  const ServoLoopStats& s = result.stats;
  std::string out;
  out += "servo loop at " + shortest_decimal(s.rate_hz) + " Hz for " + shortest_decimal(settings.seconds) +
         " s\n";
  appendf(out, "  ticks                  %llu\n", static_cast<unsigned long long>(s.ticks));
  appendf(out, "  missed_deadlines       %llu (skipped periods %llu)\n",
          static_cast<unsigned long long>(s.missed_deadlines),
          static_cast<unsigned long long>(s.skipped_periods));
  appendf(out, "  longest_stall_ms       %.3f (forces withheld %llu, deadlines re-anchored %llu)\n",
          s.longest_stall_s * 1e3, static_cast<unsigned long long>(s.forces_withheld),
          static_cast<unsigned long long>(s.deadline_reanchors));
  appendf(out, "  period_jitter_us_p50   %.1f\n", s.period_jitter_us_p50);
  appendf(out, "  period_jitter_us_p99   %.1f\n", s.period_jitter_us_p99);
  appendf(out, "  period_jitter_us_max   %.1f\n", s.period_jitter_us_max);
  appendf(out, "  wake_latency_us_max    %.1f\n", s.wake_latency_us_max);
  appendf(out, "  callback_us            mean %.2f, p99 %.2f, max %.1f\n", s.callback_us_mean,
          s.callback_us_p99, s.callback_us_max);
  appendf(out, "  realtime               SCHED_FIFO %s, CPU %s, memory locked %s\n",
          s.realtime.fifo_scheduling ? std::to_string(s.realtime.priority).c_str() : "no",
          s.realtime.cpu >= 0 ? std::to_string(s.realtime.cpu).c_str() : "not pinned",
          s.realtime.memory_locked ? "yes" : "no");
  if (!s.realtime.problems.empty())
    appendf(out, "  not obtained           %s\n", s.realtime.problems.c_str());
  if (s.fault)
    appendf(out, "  fault                  %s: %s\n", to_string(s.fault.kind), s.fault.message.c_str());
  if (result.trial) {
    const LoopBenchTrial& t = *result.trial;
    appendf(out, "  trial                  %s: %s, %zu of %zu strokes in %.2f s\n", t.characters.c_str(),
            t.end.c_str(), t.strokes_completed, t.strokes_total, t.time_s);
  }
  return out;
}

}  // namespace calligraphy::cli
