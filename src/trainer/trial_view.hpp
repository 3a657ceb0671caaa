#pragma once
// What the window shows of the trial that runs (or just ended), built on the window thread from the
// display channel: the latest snapshot, the pen's trace per stroke, the per-stroke results, and the last
// refused attempt with the library's reason.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/result.hpp"
#include "trainer/learner_text.hpp"
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

/// An attempt at a stroke that was not written: kept on the paper, faded, with the reason, until the pen
/// touches the paper again. The reason is the library's: the renderer's for an attempt that entered WS
/// (carried by the stroke_abandoned event), `match_stroke`'s on the pen-down path for one that never did.
struct RefusedStroke {
  std::uint32_t stroke_index = 0;  ///< the stroke that was to be written, over the scene
  std::uint32_t character = 0;     ///< its character, index into the scene
  std::uint32_t stroke = 0;        ///< the stroke within that character
  StrokeRefusal refusal = StrokeRefusal::none;
  bool judged_from_path = false;  ///< by match_stroke on the pen-down path (it never entered WS)
  std::vector<Vec2> points_m;     ///< the attempt's path in trial metres, for drawing
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
  /// The trial's scene and acceptance, to judge a pen-down that never entered WS (set with the trial;
  /// null: such pen-downs are not judged).
  const Scene* scene = nullptr;
  StrokeAcceptance acceptance;
  /// The last refused attempt while it is shown (not in a quiz, which gives its own verdicts).
  std::optional<RefusedStroke> refused;
  std::size_t refusals = 0;         ///< attempts refused so far (abandoned in WS or judged from the path)
  std::size_t refusals_logged = 0;  ///< of which the window has printed
  /// The last line of feedback for the learner (learner_text.hpp): the last stroke written, refused,
  /// hinted or assisted; empty before the first.
  std::optional<Feedback> feedback;
  /// A stroke the trial demonstrated and credited (stroke_assisted), shown drawn once from `at`.
  struct Shown {
    std::uint32_t character = 0;  ///< index into the scene
    std::uint32_t stroke = 0;     ///< within that character
    std::chrono::steady_clock::time_point at;
  };
  std::optional<Shown> assisted;
  /// The active stroke's hint (DisplaySnapshot::hint_shown), drawn once from `at` and then kept as a path.
  std::optional<Shown> hint;
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
  /// and the events; feeds a quiz every trace point, and finishes it when the trial ends; keeps a refused
  /// attempt. `typical_ids` gives each stroke's typical id, by stroke index in the character.
  void consume(DisplayChannel& channel, const std::vector<int>& typical_ids);

 private:
  void drain_trace(DisplayChannel& channel);
  void follow_pen(const TracePoint& point);
  void judge_pen_down_path();
  void refuse(RefusedStroke refused_stroke);
  void follow_hint();

  // The pen-down in progress (from touch-down to lift), for judging one that never enters WS.
  bool pen_down_ = false;
  bool pen_down_reached_writing_ = false;
  std::uint64_t touch_down_tick_ = 0;
  std::uint32_t pen_down_stroke_index_ = 0;
  std::vector<Vec2> pen_down_path_m_;
};

/// Each stroke's typical id, by stroke index in `character`: what TrialView::consume takes.
[[nodiscard]] std::vector<int> typical_ids_of(const Character& character);

}  // namespace calligraphy::trainer
