#pragma once
/// \file result.hpp
/// What a trial returns: the metrics, the trace, how it ended, and the servo loop's statistics when it
/// ran in real time.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/recorder.hpp"

namespace calligraphy {

/// How a trial ended.
enum class TrialEnd {
  completed,     ///< every stroke written, each in its turn
  time_limit,    ///< `max_duration_s` ran out first
  device_fault,  ///< the device returned a fault code (`TrialResult::device_fault`), or a callback threw
  watchdog,      ///< the servo loop stalled longer than its bound
  interrupted,   ///< `TrialOptions::should_stop` (e.g. SIGINT or SIGTERM, a closed window)
  gave_up,       ///< the hand moving the device (hand.hpp) stopped before every stroke was written
  /// The hand finished what it meant to write (TrialHand::finished) before the display took every stroke:
  /// strokes out of order or not taken, or given up on and left (a simulated writer, docs/writer.md).
  writer_finished,
};

/// "completed", "time_limit", "device_fault", "watchdog", "interrupted", "gave_up", "writer_finished".
[[nodiscard]] const char* to_string(TrialEnd end) noexcept;

/// The outcome of a trial. The metrics and trace hold every tick recorded, whatever ended the trial.
struct TrialResult {
  TrialMetrics metrics;
  std::vector<TrialSample> trace;  ///< one sample per tick, when `keep_trace`
  TrialEnd end = TrialEnd::completed;
  bool aborted = false;  ///< every end but `completed`
  /// For `TrialEnd::device_fault` ended by the device: its fault code (device_fault.hpp); else none.
  DeviceFault device_fault = DeviceFault::none;
  /// For a device fault `device_fault_message(device_fault, model)`; the loop's message for another
  /// fault; else a short reason or empty.
  std::string abort_reason;
  std::optional<ServoLoopStats> loop;  ///< the servo loop's statistics, for a real-time trial
  /// The device's own time stamp [s] of the first tick (`DeviceState::time_s`): the trace's and the
  /// metrics' times count from it, so t = 0 is the trial's first tick on every device. Device time of a
  /// sample = its t + this.
  double device_time_at_start_s = 0.0;
  /// The rate the ticks came at by the device's clock [Hz]: (ticks - 1) over the time from the first tick to
  /// the last; 0 for fewer than 2 ticks or a clock that did not move. The renderer assumed
  /// `TrialOptions::rate_hz`; ticks at another rate (more than 10 % off over 100 ticks or more) are logged as
  /// a warning with the measured rate when the trial finishes (`TrialSession::finish`: late ticks on a loop
  /// that checked the rates at start), since time-based parts of the force law (fades, filters, replay) ran at
  /// the wrong speed.
  double device_tick_rate_hz = 0.0;
};

/// The trace as pen samples in the paper plane: the pen is down when the HIP is at most
/// kPenContactThresholdM above the scene's paper (the rule of the pen-trace CSV reader). Samples as `trace`.
[[nodiscard]] std::vector<PenSample> pen_samples(const Scene& scene, std::span<const TrialSample> trace);

/// The one metrics record (analysis/writing_metrics.hpp) of the trial's trace, with the renderer's stroke
/// acceptance: what `calligraphy trial`, study records and Python report. Needs the trace (`keep_trace`);
/// without one nothing was written as far as the record can tell. Throws what `writing_metrics` throws.
[[nodiscard]] WritingMetrics trial_writing_metrics(const Scene& scene, const TrialResult& result,
                                                   const StrokeAcceptance& acceptance);

}  // namespace calligraphy
