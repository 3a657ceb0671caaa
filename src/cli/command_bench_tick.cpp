// `calligraphy bench tick [--json] [--chars CHARS] [--passes N] [--rate HZ] [--data DIR]`: the cost of
// one full servo tick (state machine, collision, force law, smoothing, safety chain) over real trials.
// Device states are recorded from guided simulated trials of each character (novice writer, seed 1),
// then replayed through a fresh Renderer, timing each `Renderer::tick` with steady_clock.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"

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
    const DeviceState state = device.read_state();
    states.push_back(state);
    const RenderOutput out = renderer.tick(state);
    device.write_force(out.force_n);
    if (out.finished) break;
    writer.observe(out, state);
    if (writer.done()) break;
    device.advance(dt);
  }
  return states;
}

double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  const auto index = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size()))) - 1;
  return sorted[std::min(index, sorted.size() - 1)];
}

}  // namespace

int command_bench_tick(const Args& args) {
  Args rest = args;
  if (!rest.empty() && rest[0] == "tick") rest.erase(rest.begin());
  const Arguments arguments(rest, {"chars", "passes", "rate", "data"}, {"json"});
  if (!arguments.positionals().empty()) throw UsageError("bench tick takes no positional argument");
  const std::u32string chars = characters_from(arguments.option_or("chars", "永我九乙心水"));
  const double passes_number = arguments.number_or("passes", 3);
  if (!(passes_number >= 1 && passes_number <= 1000) || passes_number != std::floor(passes_number)) {
    throw UsageError("--passes expects an integer in [1, 1000]");
  }
  const int passes = static_cast<int>(passes_number);
  const double rate_hz = arguments.number_or("rate", 1000.0);
  const CharacterLibrary library = library_from(arguments);

  std::vector<double> ns;
  double sink = 0.0;  // keeps the optimiser from dropping the ticks
  for (const char32_t c : chars) {
    const Scene scene = Scene::lay_out({library.load(c)});
    const std::vector<DeviceState> states = record_states(scene, rate_hz, 300.0);
    RendererOptions options;
    options.rate_hz = rate_hz;
    Renderer renderer(scene, ForceLawParameters{}, simulated_phantom_desktop_info(), options);
    for (int pass = 0; pass < passes; ++pass) {
      renderer.reset();
      for (const DeviceState& state : states) {
        const auto start = Clock::now();
        const RenderOutput out = renderer.tick(state);
        const auto stop = Clock::now();
        sink += out.force_n.z();
        ns.push_back(
            static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count()));
      }
    }
  }
  // The cost of the two clock reads themselves, included in every figure above.
  std::vector<double> overhead;
  for (int k = 0; k < 100000; ++k) {
    const auto start = Clock::now();
    const auto stop = Clock::now();
    overhead.push_back(
        static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count()));
  }
  std::sort(ns.begin(), ns.end());
  std::sort(overhead.begin(), overhead.end());
  double mean = 0.0;
  for (double v : ns) mean += v;
  mean = ns.empty() ? 0.0 : mean / static_cast<double>(ns.size());

  std::string char_text;
  for (const char32_t c : chars) {
    // UTF-8 of the BMP code points the library holds.
    if (c < 0x80) {
      char_text += static_cast<char>(c);
    } else if (c < 0x800) {
      char_text += static_cast<char>(0xC0 | (c >> 6));
      char_text += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      char_text += static_cast<char>(0xE0 | (c >> 12));
      char_text += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      char_text += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  const double median = percentile(ns, 0.5);
  const double p99 = percentile(ns, 0.99);
  const double p999 = percentile(ns, 0.999);
  if (arguments.flag("json")) {
    const nlohmann::json report = {
        {"characters", char_text},  {"rate_hz", rate_hz},
        {"passes", passes},         {"ticks", ns.size()},
        {"ns_median", median},      {"ns_p99", p99},
        {"ns_p999", p999},          {"ns_max", ns.empty() ? 0.0 : ns.back()},
        {"ns_mean", mean},          {"clock_overhead_ns_median", percentile(overhead, 0.5)},
        {"target_ns_median", 1000}, {"target_ns_p999", 10000}};
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    std::printf(
        "servo tick (state machine, collision, force law, smoothing, safety chain) over %zu ticks of\n"
        "guided trials of %s at %.0f Hz, %d passes:\n"
        "  median %.0f ns   p99 %.0f ns   p99.9 %.0f ns   max %.0f ns   mean %.0f ns\n"
        "  (targets: median <= 1000 ns, p99.9 <= 10000 ns; includes ~%.0f ns of clock reads)\n",
        ns.size(), char_text.c_str(), rate_hz, passes, median, p99, p999, ns.empty() ? 0.0 : ns.back(), mean,
        percentile(overhead, 0.5));
  }
  return sink == 12345.678 ? 1 : 0;  // never true; uses `sink`
}

}  // namespace calligraphy::cli
