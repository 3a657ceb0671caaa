#pragma once
/// \file recorder.hpp
/// The trial recorder: turns each servo tick (the state read and what the renderer made of it) into a
/// trace sample and the trial's metrics. Usable from any loop, lock-step or real time.
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"

namespace calligraphy {

/// One servo tick of the trace.
struct TrialSample {
  double time_s = 0.0;
  /// HIP as read from the device [m]; for a reading the renderer rejected (`RenderOutput::input_rejected`:
  /// not finite, or beyond kMaxDeviceReadingM) the last accepted one (the origin before any).
  Vec3 position_m = Vec3::Zero();
  Vec3 force_n = Vec3::Zero();  ///< commanded force [N]
  InteractionState state = InteractionState::separation;
  std::size_t stroke = 0;   ///< active stroke, counted over the whole scene (0-based)
  std::size_t element = 0;  ///< active element within it
  /// The attempt at a stroke this tick belongs to, 1-based; 0 outside any. The renderer's count (times WS
  /// was entered on the active stroke) as recorded; a simulated writer's own count (its log: an attempt runs
  /// from setting off to lifting, pen up or down) once `mark_writer_attempts` (sim/trace_attempts.hpp) ran.
  int attempt = 0;
  /// Part of an attempt at a stroke that was written again later (cleared, refused, not taken): not the
  /// final writing. From the renderer, the WS ticks of a cleared attempt; from a simulated writer's log,
  /// every tick of an attempt followed by another at the same stroke.
  bool rewritten = false;
};

/// Metrics of one stroke. Deviations are distances in the paper plane from the pen tip to the stroke's
/// reference elements [m], over the WS ticks of the stroke's last attempt (an abandoned attempt is
/// cleared, as its trace is on screen, section 4.3.3; the attempt under way when the trial ends counts up
/// to its end). They are absent (nullopt) when that attempt has no WS tick: a stroke never written, or one
/// whose last attempt was abandoned; never a 0 that would read as a perfect stroke.
struct StrokeMetrics {
  std::size_t index = 0;  ///< over the whole scene, 0-based
  std::size_t character = 0;
  int typical_id = 0;
  bool completed = false;  ///< written by the pen
  /// Credited as assisted after `assist_after_misses` refused attempts (StrokeAcceptance): demonstrated,
  /// not written; `completed` stays false.
  bool assisted = false;
  int attempts = 0;                        ///< times WS was entered on this stroke
  std::optional<double> mean_deviation_m;  ///< [m]; nullopt without a WS tick (see above)
  std::optional<double> max_deviation_m;   ///< [m]; nullopt without a WS tick
  double time_s = 0.0;          ///< from entering WS to writing the last feature point, last attempt
  std::size_t trace_begin = 0;  ///< the last attempt's samples in the trace: [trace_begin, trace_end)
  std::size_t trace_end = 0;
};

/// Metrics of a whole trial.
struct TrialMetrics {
  std::size_t strokes_total = 0;
  std::size_t strokes_completed = 0;  ///< strokes written by the pen
  std::size_t strokes_assisted = 0;   ///< strokes credited as assisted (StrokeMetrics::assisted), apart
  bool completed_in_order = false;    ///< every stroke written, each in its turn (none assisted)
  double time_s = 0.0;                ///< from the start to the last stroke written (or the end of the trial)
  /// Over all WS ticks of the strokes' last attempts [m]; nullopt when no stroke has one (nothing was
  /// written).
  std::optional<double> mean_deviation_m;
  std::optional<double> max_deviation_m;  ///< [m]; nullopt when no stroke has a WS tick
  double max_force_n = 0.0;               ///< max |F| commanded
  double max_force_step_n = 0.0;          ///< max |F(k) - F(k-1)| between consecutive ticks
  std::size_t state_transitions = 0;
  /// Ticks whose device reading the renderer rejected (`RenderOutput::input_rejected`: not finite, or a
  /// coordinate beyond kMaxDeviceReadingM): each commanded zero force and is kept at the last accepted
  /// position, so the trace alone cannot show them.
  std::size_t readings_rejected = 0;
  std::vector<StrokeMetrics> per_stroke;
};

/// Records ticks into a trace and metrics. Allocates only when the trace grows beyond `reserve`.
class TrialRecorder {
 public:
  /// `scene` must outlive the recorder.
  explicit TrialRecorder(const Scene& scene, bool keep_trace = true);
  /// Record one tick: the state read from the device and what the renderer made of it.
  void record(const DeviceState& state, const RenderOutput& output);
  [[nodiscard]] const TrialMetrics& metrics() const noexcept { return metrics_; }
  [[nodiscard]] const std::vector<TrialSample>& trace() const noexcept { return trace_; }
  /// Moves the trace out (a long trial's trace is large: no copy); the recorder's trace is empty after.
  [[nodiscard]] std::vector<TrialSample> take_trace() noexcept { return std::move(trace_); }
  /// Allocates (and touches) room for `ticks` samples of the trace, so that the next `ticks` calls of
  /// `record` never allocate: for a real-time loop. Nothing when the trace is not kept.
  void reserve(std::size_t ticks);
  /// Room for `ticks` samples without touching it (std::vector::reserve): the trace does not move while it
  /// grows to that size. Nothing when the trace is not kept.
  void reserve_untouched(std::size_t ticks);
  /// Closes the metrics at `end_time_s` (time_s of an unfinished trial); the deviations of the attempt
  /// under way, if it has WS ticks, are added to its stroke and to the totals.
  void finish(double end_time_s);

 private:
  struct Attempt {  // the WS ticks of the current stroke's attempt under way
    double sum = 0.0;
    std::size_t count = 0;
    double max = 0.0;
    double start_time = 0.0;
  };
  const Scene* scene_;
  bool keep_trace_;
  std::vector<TrialSample> trace_;
  TrialMetrics metrics_;
  std::vector<std::pair<std::size_t, std::size_t>> stroke_location_;  // global index -> (character, stroke)
  std::size_t current_ = 0;                                           // stroke being written (global index)
  std::size_t ticks_ = 0;  // ticks recorded: the next sample's index in the trace
  Attempt attempt_;
  Vec3 last_force_ = Vec3::Zero();
  Vec3 last_position_ = Vec3::Zero();  // the last reading the renderer accepted
  bool first_ = true;
  InteractionState last_state_ = InteractionState::separation;
  double pooled_sum_ = 0.0;
  std::size_t pooled_count_ = 0;
  double last_time_ = 0.0;
  void close_attempt(StrokeMetrics& stroke);  // the attempt's deviations to `stroke` and the totals
};

}  // namespace calligraphy
