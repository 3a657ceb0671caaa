// The servo-to-display channel and the publisher TrialSession drives (display.hpp).
#include "calligraphy/trial/display.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

DisplayPoint3 point3(const Vec3& v) { return DisplayPoint3{v.x(), v.y(), v.z()}; }

std::uint32_t narrow(std::size_t value) { return static_cast<std::uint32_t>(value); }

}  // namespace

const char* to_string(DisplayEventKind kind) noexcept {
  switch (kind) {
    case DisplayEventKind::stroke_completed:
      return "stroke_completed";
    case DisplayEventKind::stroke_abandoned:
      return "stroke_abandoned";
    case DisplayEventKind::stroke_assisted:
      return "stroke_assisted";
    case DisplayEventKind::character_completed:
      return "character_completed";
    case DisplayEventKind::trial_ended:
      return "trial_ended";
  }
  return "unknown";
}

void DisplayChannelOptions::validate() const {
  if (event_capacity == 0 || event_capacity > (std::size_t{1} << 24)) {
    throw InvalidArgument("DisplayChannelOptions.event_capacity = " + std::to_string(event_capacity) +
                          " must be in [1, 16777216]");
  }
  if (trace_capacity == 0 || trace_capacity > (std::size_t{1} << 24)) {
    throw InvalidArgument("DisplayChannelOptions.trace_capacity = " + std::to_string(trace_capacity) +
                          " must be in [1, 16777216]");
  }
  if (trace_every_ticks < 1 || trace_every_ticks > 1000) {
    throw InvalidArgument("DisplayChannelOptions.trace_every_ticks = " + std::to_string(trace_every_ticks) +
                          " must be in [1, 1000]");
  }
}

DisplayChannel::DisplayChannel(const DisplayChannelOptions& options)
    : options_((options.validate(), options)),
      events_(options.event_capacity),
      trace_(options.trace_capacity) {}

DisplayPublisher::DisplayPublisher(const Scene& scene, DisplayChannel& channel)
    : scene_(&scene), channel_(&channel) {
  std::uint32_t first = 0;
  for (const PlacedCharacter& character : scene.characters) {
    first_stroke_.push_back(first);
    first += narrow(character.strokes.size());
  }
  last_.strokes_total = first;
  if (!scene.characters.empty() && !scene.characters.front().strokes.empty()) {
    const Vec2& start = scene.characters.front().strokes.front().start();
    last_.hint_m = DisplayPoint2{start.x(), start.y()};
  }
}

void DisplayPublisher::publish_tick(std::uint64_t tick, const DeviceState& state, const RenderOutput& output,
                                    const TrialMetrics& metrics) noexcept {
  DisplaySnapshot& s = last_;
  s.tick = tick;
  s.time_s = state.time_s;
  s.published_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now().time_since_epoch())
                       .count();
  s.state = output.state;
  s.finished = output.finished;
  s.in_constraint_space = output.in_constraint_space;
  s.strokes_completed = narrow(metrics.strokes_completed);
  s.misses = output.misses;
  s.hint_shown = output.hint_shown;
  if (!output.finished && output.character < scene_->characters.size()) {
    const PlacedCharacter& character = scene_->characters[output.character];
    s.character = narrow(output.character);
    s.stroke = narrow(output.stroke);
    s.element = narrow(output.element);
    s.stroke_index = first_stroke_[output.character] + narrow(output.stroke);
    if (output.stroke < character.strokes.size()) {
      const Vec2& start = character.strokes[output.stroke].start();
      s.hint_m = DisplayPoint2{start.x(), start.y()};
    }
  } else {
    s.stroke_index = s.strokes_total;  // past the last stroke; character and hint stay on the last one
  }
  s.hip_m = point3(state.position_m);
  s.force_n = point3(output.force_n);
  const double paper_z = scene_->layout.paper_z_m;
  s.vtp_m = s.hip_m;
  s.vtp_m.z = std::max(s.hip_m.z, paper_z);
  s.pen_height_m = state.position_m.z() - paper_z;
  channel_->publish(s);

  // The recorder closes strokes in order, written or assisted: the one closed this tick is the last one.
  const std::size_t closed = metrics.strokes_completed + metrics.strokes_assisted;
  const std::uint32_t every = channel_->options().trace_every_ticks;
  if (every == 1 || tick % every == 0) {
    // The tick that completes a stroke still belongs to it (as in the recorder's trace).
    const std::uint32_t stroke_written = (output.stroke_completed || output.stroke_assisted) && closed > 0
                                             ? narrow(closed - 1)
                                             : s.stroke_index;
    channel_->push_trace(TracePoint{tick, state.time_s, s.hip_m, output.state, stroke_written});
  }

  const StrokeMetrics* last_closed =
      closed > 0 && closed <= metrics.per_stroke.size() ? &metrics.per_stroke[closed - 1] : nullptr;
  const auto stroke_event = [&](DisplayEventKind kind, const StrokeMetrics& m) {
    DisplayEvent e;
    e.kind = kind;
    e.tick = tick;
    e.time_s = state.time_s;
    e.character = narrow(m.character);
    e.stroke_index = narrow(m.index);
    e.stroke = e.stroke_index - first_stroke_[m.character];
    e.strokes_completed = s.strokes_completed;
    e.attempts = m.attempts;
    return e;
  };
  if (output.stroke_abandoned) {
    DisplayEvent e;
    if (output.stroke_assisted && last_closed != nullptr) {
      e = stroke_event(DisplayEventKind::stroke_abandoned, *last_closed);
    } else {
      e.kind = DisplayEventKind::stroke_abandoned;
      e.tick = tick;
      e.time_s = state.time_s;
      e.character = s.character;
      e.stroke = s.stroke;
      e.stroke_index = s.stroke_index;
      e.strokes_completed = s.strokes_completed;
    }
    e.refusal = output.refusal;
    channel_->push_event(e);
  }
  if (output.stroke_assisted && last_closed != nullptr) {
    DisplayEvent e = stroke_event(DisplayEventKind::stroke_assisted, *last_closed);
    e.mean_deviation_m = std::numeric_limits<double>::quiet_NaN();
    e.max_deviation_m = std::numeric_limits<double>::quiet_NaN();
    channel_->push_event(e);
    if (e.stroke + 1 == scene_->characters[last_closed->character].strokes.size()) {
      e.kind = DisplayEventKind::character_completed;
      channel_->push_event(e);
    }
  }
  if (output.stroke_completed && last_closed != nullptr) {
    const StrokeMetrics& m = *last_closed;
    DisplayEvent e = stroke_event(DisplayEventKind::stroke_completed, m);
    e.mean_deviation_m = m.mean_deviation_m.value_or(std::numeric_limits<double>::quiet_NaN());
    e.max_deviation_m = m.max_deviation_m.value_or(std::numeric_limits<double>::quiet_NaN());
    e.stroke_time_s = m.time_s;
    channel_->push_event(e);
    if (e.stroke + 1 == scene_->characters[m.character].strokes.size()) {
      e.kind = DisplayEventKind::character_completed;
      channel_->push_event(e);
    }
  }
}

void DisplayPublisher::publish_end(TrialEnd end, double time_s) noexcept {
  channel_->publish(last_);
  DisplayEvent e;
  e.kind = DisplayEventKind::trial_ended;
  e.tick = last_.tick;
  e.time_s = time_s;
  e.character = last_.character;
  e.stroke = last_.stroke;
  e.stroke_index = last_.stroke_index;
  e.strokes_completed = last_.strokes_completed;
  e.end = end;
  channel_->push_event(e);
}

}  // namespace calligraphy
