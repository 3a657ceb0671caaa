#include "eval/tick_cost.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "eval/report_numbers.hpp"

namespace calligraphy::cli {
namespace {

using Clock = std::chrono::steady_clock;

// The device states a guided trial reads, lock-step as in run_simulated_trial.
std::vector<DeviceState> record_states(const Scene& scene, double rate_hz, double max_duration_s) {
  SimulatedDevice device;
  SimulatedWriter writer(scene, WriterProfile::novice(), 1);
  RendererOptions options;
  options.rate_hz = rate_hz;
  Renderer renderer(scene, ForceLawParameters{}, device.info(), options);
  device.attach_hand(&writer);
  device.open();
  std::vector<DeviceState> states;
  const double dt = 1.0 / rate_hz;
  const auto ticks = static_cast<std::size_t>(max_duration_s * rate_hz);
  for (std::size_t k = 0; k < ticks; ++k) {
    DeviceState state;
    if (device.read_state(state) != DeviceFault::none) break;  // an open simulated device has no faults
    states.push_back(state);
    const RenderOutput out = renderer.tick(state);
    if (device.write_force(out.force_n) != DeviceFault::none) break;
    if (out.finished) break;
    writer.observe(out, state);
    if (writer.done()) break;
    device.advance(dt);
  }
  return states;
}

double nanoseconds(Clock::time_point start, Clock::time_point stop) {
  return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
}

}  // namespace

TickCost measure_tick_cost(const CharacterLibrary& library, const TickCostSettings& settings) {
  if (settings.passes < 1) throw InvalidArgument("tick cost: passes must be >= 1");
  if (settings.characters.empty()) throw InvalidArgument("tick cost: no character given");
  TickCost cost;
  cost.rate_hz = settings.rate_hz;
  cost.passes = settings.passes;
  for (const char32_t c : settings.characters) cost.characters += encode_utf8(c);
  std::vector<double> ns;
  for (const char32_t c : settings.characters) {
    const Scene scene = Scene::lay_out({library.load(c)});
    const std::vector<DeviceState> states = record_states(scene, settings.rate_hz, settings.max_duration_s);
    RendererOptions options;
    options.rate_hz = settings.rate_hz;
    Renderer renderer(scene, ForceLawParameters{}, simulated_phantom_desktop_info(), options);
    for (int pass = 0; pass < settings.passes; ++pass) {
      renderer.reset();
      for (const DeviceState& state : states) {
        const auto start = Clock::now();
        const RenderOutput out = renderer.tick(state);
        const auto stop = Clock::now();
        cost.force_sum_n += out.force_n.z();
        ns.push_back(nanoseconds(start, stop));
      }
    }
  }
  std::vector<double> overhead;
  for (int k = 0; k < 100000; ++k) {
    const auto start = Clock::now();
    const auto stop = Clock::now();
    overhead.push_back(nanoseconds(start, stop));
  }
  std::sort(ns.begin(), ns.end());
  std::sort(overhead.begin(), overhead.end());
  double sum = 0.0;
  for (double v : ns) sum += v;
  cost.ticks = ns.size();
  cost.ns_mean = ns.empty() ? 0.0 : sum / static_cast<double>(ns.size());
  cost.ns_median = nearest_rank(ns, 0.5);
  cost.ns_p99 = nearest_rank(ns, 0.99);
  cost.ns_p999 = nearest_rank(ns, 0.999);
  cost.ns_max = ns.empty() ? 0.0 : ns.back();
  cost.clock_overhead_ns_median = nearest_rank(overhead, 0.5);
  return cost;
}

std::string tick_cost_json(const TickCost& c) {
  const nlohmann::json report = {
      {"characters", c.characters}, {"rate_hz", c.rate_hz},
      {"passes", c.passes},         {"ticks", c.ticks},
      {"ns_median", c.ns_median},   {"ns_p99", c.ns_p99},
      {"ns_p999", c.ns_p999},       {"ns_max", c.ns_max},
      {"ns_mean", c.ns_mean},       {"clock_overhead_ns_median", c.clock_overhead_ns_median},
      {"target_ns_median", 1000},   {"target_ns_p999", 10000}};
  return report.dump(2) + "\n";
}

std::string tick_cost_text(const TickCost& c) {
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "servo tick (state machine, collision, force law, smoothing, safety chain) over %zu ticks of\n"
      "guided trials of %s at %.0f Hz, %d passes:\n"
      "  median %.0f ns   p99 %.0f ns   p99.9 %.0f ns   max %.0f ns   mean %.0f ns\n"
      "  (targets: median <= 1000 ns, p99.9 <= 10000 ns; includes ~%.0f ns of clock reads)\n",
      c.ticks, c.characters.c_str(), c.rate_hz, c.passes, c.ns_median, c.ns_p99, c.ns_p999, c.ns_max,
      c.ns_mean, c.clock_overhead_ns_median);
  return text;
}

}  // namespace calligraphy::cli
