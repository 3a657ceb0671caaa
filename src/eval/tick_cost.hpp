#pragma once
// The cost of one full servo tick (state machine, collision, force law, smoothing, safety chain) over
// real trials: device states are recorded from guided simulated trials of each character (novice
// writer, seed 1, lock-step as in run_simulated_trial), then replayed through a fresh Renderer, timing
// each `Renderer::tick` with steady_clock. What `calligraphy bench tick` runs (docs/force-rendering.md).
#include <cstddef>
#include <string>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::cli {

struct TickCostSettings {
  std::u32string characters = U"永我九乙心水";
  int passes = 3;                 ///< replays of each recorded trial, >= 1
  double rate_hz = 1000.0;        ///< servo rate of the recorded trials and the renderer [Hz]
  double max_duration_s = 300.0;  ///< longest recorded trial [s]
};

struct TickCost {
  std::string characters;  ///< UTF-8
  double rate_hz = 0.0;
  int passes = 0;
  std::size_t ticks = 0;  ///< ticks timed, over all passes
  double ns_median = 0.0, ns_p99 = 0.0, ns_p999 = 0.0, ns_max = 0.0, ns_mean = 0.0;
  double clock_overhead_ns_median = 0.0;  ///< the two clock reads included in every figure above
  double force_sum_n = 0.0;               ///< sum of the forces' z: makes the ticks' results observable
};

/// Records and times the ticks. Throws CharacterNotFound, and InvalidArgument for bad settings.
TickCost measure_tick_cost(const CharacterLibrary& library, const TickCostSettings& settings);

/// The JSON report (keys characters, rate_hz, passes, ticks, ns_median, ns_p99, ns_p999, ns_max, ns_mean,
/// clock_overhead_ns_median, target_ns_median, target_ns_p999), newline-terminated.
std::string tick_cost_json(const TickCost& cost);
/// The same for people.
std::string tick_cost_text(const TickCost& cost);

}  // namespace calligraphy::cli
