#pragma once
// What the window shows of the trial that runs (or just ended), built on the window thread from the
// display channel: the latest snapshot, the pen's trace per stroke, the per-stroke results.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/result.hpp"
#include "trainer/live_quiz.hpp"

namespace calligraphy::trainer {

struct StrokeResult {
  std::uint32_t stroke = 0;  ///< within the character, 0-based
  int typical_id = 0;
  double mean_deviation_m = 0.0;
  double max_deviation_m = 0.0;
  double time_s = 0.0;
  int attempts = 0;
};

/// A piece of the pen's trace while writing (WS), in trial metres.
struct TraceSegment {
  std::uint32_t stroke_index = 0;
  std::uint64_t first_tick = 0;
  std::vector<Vec2> points_m;
};

struct TrialView {
  std::size_t character = 0;  ///< index in the row
  bool whole_row = false;     ///< the trial's scene is the whole row (a study trial), not one character
  std::size_t number = 0;     ///< trials started so far, this one included
  bool guidance = true;
  std::string condition;  ///< "vision+haptic" or "vision"
  DisplaySnapshot snapshot;
  std::vector<TraceSegment> segments;
  bool segment_open = false;
  std::vector<StrokeResult> results;
  std::size_t abandoned = 0;
  bool ended = false;  ///< the trial_ended event arrived
  TrialEnd end = TrialEnd::completed;
  // Filled in when the worker's result is taken.
  bool have_result = false;
  TrialMetrics metrics;
  std::string end_reason;
  std::string saved_as;    ///< the JSON file, or empty
  std::string save_error;  ///< why saving failed, or empty
  /// A quiz trial: each stroke judged as the pen lifts, fed from the trace queue (live_quiz.hpp).
  std::optional<LiveQuiz> quiz;
  /// The quiz's events not yet logged, "CHARACTER-INDEX stroke k: kind (...)" lines for stderr.
  std::vector<std::pair<std::size_t, QuizEvent>> quiz_unlogged;

  /// Copies the latest snapshot (keeping the last one when a publish overlapped) and drains the trace
  /// and the events; feeds a quiz every trace point, and finishes it when the trial ends. `typical_ids` gives
  /// each stroke's typical id, by stroke index in the character.
  void consume(DisplayChannel& channel, const std::vector<int>& typical_ids);

 private:
  void drain_trace(DisplayChannel& channel);
};

}  // namespace calligraphy::trainer
