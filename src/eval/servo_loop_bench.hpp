#pragma once
// `calligraphy bench loop`: the real-time ServoLoop run for a while, either free (the simulated device
// with no hand, held near its start by a weak virtual spring) or through a whole real-time simulated
// trial, and its statistics: period jitter, missed deadlines, stalls, callback time (docs/servo-loop.md).
#include <functional>
#include <optional>
#include <string>

#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"

namespace calligraphy::cli {

struct LoopBenchSettings {
  ServoLoopOptions loop{};
  double seconds = 10.0;                 ///< how long the free loop runs; the trial's time limit [s]
  std::string realtime_mode = "ignore";  ///< enforce|ignore|off, as given; reported only
  std::u32string trial_characters;       ///< empty: the free loop; else a real-time trial of these
  /// Polled every few milliseconds: true ends the run early (the trial ends `interrupted`). May be empty.
  std::function<bool()> should_stop;
};

/// What the trial of a loop bench did.
struct LoopBenchTrial {
  std::string characters;  ///< UTF-8
  std::string end;         ///< to_string(TrialEnd)
  std::size_t strokes_completed = 0;
  std::size_t strokes_total = 0;
  double time_s = 0.0;
};

struct LoopBenchResult {
  ServoLoopStats stats;
  std::optional<LoopBenchTrial> trial;
};

/// Runs the loop. `library` gives the trial's characters. Throws as ServoLoop::start (RealtimeError with
/// `enforce`), InvalidArgument for bad options, CharacterNotFound.
LoopBenchResult run_loop_bench(const CharacterLibrary& library, const LoopBenchSettings& settings);

/// The statistics as a JSON object with `seconds`, `realtime_mode` and, for a trial, `trial`.
std::string loop_bench_json(const LoopBenchResult& result, const LoopBenchSettings& settings);
/// The same for people.
std::string loop_bench_text(const LoopBenchResult& result, const LoopBenchSettings& settings);

}  // namespace calligraphy::cli
