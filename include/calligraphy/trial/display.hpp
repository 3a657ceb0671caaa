#pragma once
/// \file display.hpp
/// What a trial shows while it runs, handed from the servo thread to an application's display thread
/// without locks: the paper's system draws the standard character when the haptic loop starts (section
/// 2.2) and, while the pen is guided, the reference in blue, the active character in yellow, the pen's
/// trajectory in light green and a red ellipse at the start of the active stroke (section 7.2).
///
/// A `DisplayChannel` carries three things from one producer (the thread that steps the trial) to the
/// display:
///   - the latest `DisplaySnapshot` (state, active stroke, hint, HIP, VTP, force, pen height, counters),
///     through a `Seqlock`: any thread reads the latest whole snapshot, never a torn one;
///   - `DisplayEvent`s (stroke completed with its metrics, stroke abandoned, character completed, trial
///     ended) through a single-producer single-consumer lock-free queue, drained off the servo thread;
///   - `TracePoint`s, the pen's positions tick by tick, through another such queue, for drawing.
/// Publishing never allocates, locks, waits or logs: a full queue drops the value and counts it.
///
///     DisplayChannel channel;
///     TrialOptions options;
///     options.display = &channel;                  // the session publishes after every tick
///     std::thread trial([&] { result = run_trial(device, scene, options); });
///     while (drawing) {                            // the application's display loop
///       DisplaySnapshot now;
///       channel.try_latest(now);                   // never waits on the servo thread
///       for (DisplayEvent e; channel.poll_event(e);) ...
///       for (TracePoint p; channel.poll_trace(p);) ...
///     }
#include <cstddef>
#include <cstdint>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/core/seqlock.hpp"
#include "calligraphy/core/spsc_queue.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

/// A point in the paper plane [m] (trivially copyable, unlike Eigen's vectors).
struct DisplayPoint2 {
  double x = 0.0;
  double y = 0.0;
};
/// A point or vector in device space, [m] or [N] as named by its field.
struct DisplayPoint3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

/// The display's view of one servo tick. Device coordinates: x right, y away from the writer, z up out
/// of the paper, in metres.
struct DisplaySnapshot {
  std::uint64_t tick = 0;  ///< ticks stepped so far (0: nothing published yet)
  /// The tick's time [s] as the publisher was given it: from a `TrialSession`, the trial's clock (device
  /// time since the trial's first tick, so 0 at tick 1), not the device's own time stamp.
  double time_s = 0.0;
  std::int64_t published_ns = 0;  ///< std::chrono::steady_clock time of publishing [ns], for latency
  InteractionState state = InteractionState::separation;  ///< SS, AS, CS or WS (Table 1)
  bool finished = false;                                  ///< every stroke of the scene is written
  bool in_constraint_space = false;  ///< the tip is inside the active element's constraint space
  std::uint32_t character = 0;       ///< active character, index into the scene
  std::uint32_t stroke = 0;          ///< active stroke within its character
  std::uint32_t element = 0;         ///< active element within the stroke
  std::uint32_t stroke_index = 0;    ///< active stroke counted over the scene (0-based)
  std::uint32_t strokes_completed = 0;
  std::uint32_t strokes_total = 0;
  std::uint32_t misses = 0;  ///< refused attempts on the active stroke
  bool hint_shown = false;   ///< the active stroke is shown as a hint (misses >= hint_after_misses)
  DisplayPoint2 hint_m;      ///< the active stroke's start, where the red ellipse goes [m]
  DisplayPoint3 hip_m;       ///< haptic interface point, as read from the device [m]
  /// Virtual pen tip: the HIP projected onto the paper when it is below the paper, else the HIP [m]
  /// (section 4.2: the VTP stays on the surface the HIP penetrates).
  DisplayPoint3 vtp_m;
  DisplayPoint3 force_n;      ///< the force commanded this tick [N]
  double pen_height_m = 0.0;  ///< HIP z minus the paper's z [m]; negative: depth below the paper
};

enum class DisplayEventKind : std::uint8_t {
  stroke_completed,     ///< the last feature point of a stroke was written; its metrics are set
  stroke_abandoned,     ///< the pen left the paper in WS unwritten (4.3.3); `refusal` says why
  stroke_assisted,      ///< the stroke was demonstrated and credited after assist_after_misses misses
  character_completed,  ///< the last stroke of a character was written
  trial_ended,          ///< `TrialSession::finish` was called; `end` says how
};

/// "stroke_completed", "stroke_abandoned", "stroke_assisted", "character_completed" or "trial_ended".
[[nodiscard]] const char* to_string(DisplayEventKind kind) noexcept;

/// Something that happened at one tick, for the display to show once.
struct DisplayEvent {
  DisplayEventKind kind = DisplayEventKind::stroke_completed;
  std::uint64_t tick = 0;               ///< the tick it happened at (1-based, as `DisplaySnapshot::tick`)
  double time_s = 0.0;                  ///< the tick's time [s], on the clock of `DisplaySnapshot::time_s`
  std::uint32_t character = 0;          ///< the character it concerns
  std::uint32_t stroke = 0;             ///< the stroke within that character (stroke events)
  std::uint32_t stroke_index = 0;       ///< the stroke counted over the scene (stroke events)
  std::uint32_t strokes_completed = 0;  ///< strokes written so far, this one included
  // stroke_completed: the stroke's metrics (recorder.hpp `StrokeMetrics`)
  double mean_deviation_m = 0.0;  ///< mean distance from the stroke over its last attempt [m]; NaN: none
  double max_deviation_m = 0.0;   ///< largest such distance [m]
  double stroke_time_s = 0.0;     ///< from entering WS to the last feature point [s]
  std::int32_t attempts = 0;      ///< times WS was entered on the stroke (also stroke_assisted)
  // stroke_abandoned: why the attempt was refused (the renderer's `RenderOutput::refusal`)
  StrokeRefusal refusal = StrokeRefusal::none;
  // trial_ended
  TrialEnd end = TrialEnd::completed;
};

/// The pen at one tick, for drawing its trajectory.
struct TracePoint {
  std::uint64_t tick = 0;
  double time_s = 0.0;  ///< the tick's time [s], on the clock of `DisplaySnapshot::time_s`
  DisplayPoint3 hip_m;  ///< [m]
  InteractionState state = InteractionState::separation;
  /// The stroke over the scene the point belongs to: the active one, or the one this tick completed.
  std::uint32_t stroke_index = 0;
};

/// Queue sizes of a `DisplayChannel`.
struct DisplayChannelOptions {
  std::size_t event_capacity = 1024;  ///< events held until drained (a few per stroke)
  /// Trace points held until drained: 16384 is 16 s at 1 kHz, far longer than a display frame.
  std::size_t trace_capacity = 16384;
  /// Push one trace point every this many ticks (1: every tick), in [1, 1000].
  std::uint32_t trace_every_ticks = 1;
  /// Throws InvalidArgument naming the field when a value is out of range.
  void validate() const;
};

/// The servo-to-display channel. One producer thread at a time (the servo thread while a trial runs;
/// the thread that calls `TrialSession::finish` after it); `latest`/`try_latest` from any thread;
/// `poll_event` and `poll_trace` each from one consumer thread at a time.
class DisplayChannel {
 public:
  /// Allocates the queues. Throws InvalidArgument for bad options.
  explicit DisplayChannel(const DisplayChannelOptions& options = {});
  DisplayChannel(const DisplayChannel&) = delete;
  DisplayChannel& operator=(const DisplayChannel&) = delete;

  // ---- Producer: never allocates, locks, waits or logs.
  void publish(const DisplaySnapshot& snapshot) noexcept { snapshot_.store(snapshot); }
  /// False when the event queue is full (the event is dropped and counted).
  bool push_event(const DisplayEvent& event) noexcept { return events_.try_push(event); }
  /// False when the trace queue is full (the point is dropped and counted).
  bool push_trace(const TracePoint& point) noexcept { return trace_.try_push(point); }

  // ---- Consumers.
  /// The latest snapshot (a default one before the first publish). Any thread; lock-free, retries
  /// only while a publish is in progress.
  [[nodiscard]] DisplaySnapshot latest() const noexcept { return snapshot_.load(); }
  /// The latest snapshot into `out`, or false (out unchanged) when publishes overlapped every try:
  /// for a display thread that must never wait.
  bool try_latest(DisplaySnapshot& out) const noexcept { return snapshot_.try_load(out); }
  /// The oldest event not yet polled; false when none. One consumer thread.
  bool poll_event(DisplayEvent& out) noexcept { return events_.try_pop(out); }
  /// The oldest trace point not yet polled; false when none. One consumer thread.
  bool poll_trace(TracePoint& out) noexcept { return trace_.try_pop(out); }

  [[nodiscard]] std::uint64_t publications() const noexcept { return snapshot_.version(); }
  [[nodiscard]] std::uint64_t dropped_events() const noexcept { return events_.dropped(); }
  [[nodiscard]] std::uint64_t dropped_trace_points() const noexcept { return trace_.dropped(); }
  [[nodiscard]] const DisplayChannelOptions& options() const noexcept { return options_; }

 private:
  DisplayChannelOptions options_;
  Seqlock<DisplaySnapshot> snapshot_;
  SpscQueue<DisplayEvent> events_;
  SpscQueue<TracePoint> trace_;
};

/// Publishes the ticks of one trial of `scene` into a channel: what `TrialSession` does after each
/// `step` once a channel is attached. Usable from an application's own loop with its own renderer and
/// recorder.
class DisplayPublisher {
 public:
  /// `scene` and `channel` must outlive the publisher. Allocates (the stroke table); nothing after.
  DisplayPublisher(const Scene& scene, DisplayChannel& channel);
  /// After tick `tick` (1-based): publishes the snapshot, pushes a trace point every
  /// `trace_every_ticks` ticks, and the events of the tick (`metrics` must already hold the tick: the
  /// recorder records before this is called). Servo path: no allocation, lock, wait, log or exception.
  void publish_tick(std::uint64_t tick, const DeviceState& state, const RenderOutput& output,
                    const TrialMetrics& metrics) noexcept;
  /// Pushes the `trial_ended` event (and publishes the last snapshot again). After the servo thread
  /// stopped stepping.
  void publish_end(TrialEnd end, double time_s) noexcept;
  [[nodiscard]] DisplayChannel& channel() const noexcept { return *channel_; }

 private:
  const Scene* scene_;
  DisplayChannel* channel_;
  std::vector<std::uint32_t> first_stroke_;  // per character: its first stroke's index over the scene
  DisplaySnapshot last_{};                   // the snapshot being built, kept between ticks
};

}  // namespace calligraphy
