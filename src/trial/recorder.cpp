#include <algorithm>

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy {

TrialRecorder::TrialRecorder(const Scene& scene, bool keep_trace) : scene_(&scene), keep_trace_(keep_trace) {
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    for (std::size_t s = 0; s < scene.characters[c].strokes.size(); ++s) {
      StrokeMetrics m;
      m.index = stroke_location_.size();
      m.character = c;
      m.typical_id = scene.characters[c].strokes[s].typical_id;
      metrics_.per_stroke.push_back(m);
      stroke_location_.emplace_back(c, s);
    }
  }
  metrics_.strokes_total = stroke_location_.size();
}

void TrialRecorder::record(const DeviceState& state, const RenderOutput& out) {
  last_time_ = state.time_s;
  const double force_step = first_ ? 0.0 : (out.force_n - last_force_).norm();
  metrics_.max_force_step_n = std::max(metrics_.max_force_step_n, force_step);
  metrics_.max_force_n = std::max(metrics_.max_force_n, out.force_n.norm());
  if (!first_ && out.state != last_state_) ++metrics_.state_transitions;
  first_ = false;
  last_force_ = out.force_n;
  last_state_ = out.state;

  const std::size_t index = ticks_++;
  // A reading the renderer rejected (not finite, or beyond any device's reach) is no position of the pen:
  // it is recorded at the last accepted one, and it is no tick of writing (no deviation is measured to it).
  if (out.input_rejected) {
    ++metrics_.readings_rejected;
  } else {
    last_position_ = state.position_m;
  }
  if (keep_trace_) {
    trace_.push_back({state.time_s, last_position_, out.force_n, out.state, current_, out.element});
  }
  if (current_ >= metrics_.per_stroke.size()) return;
  StrokeMetrics& m = metrics_.per_stroke[current_];
  const bool writing_this =
      !out.input_rejected && (out.state == InteractionState::writing || out.stroke_completed);
  if (out.state_changed && out.state == InteractionState::writing) {  // a new attempt starts
    attempt_ = {};
    attempt_.start_time = state.time_s;
    ++m.attempts;
    m.trace_begin = index;
  }
  if (keep_trace_ && writing_this) trace_.back().attempt = m.attempts;
  // A cleared attempt is written again: its ticks are not the final writing (no allocation: marks only).
  if (keep_trace_ && out.stroke_abandoned) {
    for (std::size_t i = m.trace_begin; i <= index && i < trace_.size(); ++i) trace_[i].rewritten = true;
  }
  if (writing_this) {
    const auto [c, s] = stroke_location_[current_];
    // To the whole reference stroke, not only the active element.
    const double d =
        distance_to_elements(scene_->characters[c].strokes[s].elements, state.position_m.head<2>());
    attempt_.sum += d;
    ++attempt_.count;
    attempt_.max = std::max(attempt_.max, d);
    m.trace_end = index + 1;
  }
  if (out.stroke_abandoned) {  // the trace of an abandoned attempt is cleared, and so are its deviations
    m.trace_end = m.trace_begin;
    attempt_ = {};
  }
  if (out.stroke_assisted) {  // credited after the last miss: the next stroke is active
    m.assisted = true;
    ++metrics_.strokes_assisted;
    metrics_.time_s = state.time_s;
    attempt_ = {};
    ++current_;
  } else if (out.stroke_completed) {
    m.completed = true;
    m.time_s = state.time_s - attempt_.start_time;
    close_attempt(m);
    ++metrics_.strokes_completed;
    metrics_.time_s = state.time_s;
    attempt_ = {};
    ++current_;
  }
}

void TrialRecorder::close_attempt(StrokeMetrics& stroke) {
  if (attempt_.count == 0) return;  // no WS tick: no deviation to report
  stroke.mean_deviation_m = attempt_.sum / static_cast<double>(attempt_.count);
  stroke.max_deviation_m = attempt_.max;
  pooled_sum_ += attempt_.sum;
  pooled_count_ += attempt_.count;
  metrics_.mean_deviation_m = pooled_sum_ / static_cast<double>(pooled_count_);
  metrics_.max_deviation_m = std::max(metrics_.max_deviation_m.value_or(0.0), attempt_.max);
}

void TrialRecorder::reserve(std::size_t ticks) {
  if (!keep_trace_ || ticks <= trace_.capacity()) return;
  const std::size_t size = trace_.size();
  trace_.resize(ticks);  // value-initialises, so the pages are touched now, not in the loop
  trace_.resize(size);
}

void TrialRecorder::reserve_untouched(std::size_t ticks) {
  if (keep_trace_) trace_.reserve(ticks);
}

void TrialRecorder::finish(double end_time_s) {
  if (current_ < metrics_.per_stroke.size()) {  // the stroke under way when the trial ended
    close_attempt(metrics_.per_stroke[current_]);
    attempt_ = {};
  }
  metrics_.completed_in_order =
      metrics_.strokes_total > 0 && metrics_.strokes_completed == metrics_.strokes_total;
  if (!metrics_.completed_in_order) metrics_.time_s = std::max(end_time_s, last_time_);
}

}  // namespace calligraphy
