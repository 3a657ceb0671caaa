#include "trainer/trial_view.hpp"

#include <algorithm>

namespace calligraphy::trainer {
namespace {

// Points closer than this to the last one kept are not kept: the trace is drawn, not analysed.
constexpr double kTraceStepM = 0.0001;

}  // namespace

void TrialView::consume(DisplayChannel& channel, const std::vector<int>& typical_ids) {
  channel.try_latest(snapshot);
  drain_trace(channel);
  for (DisplayEvent e; channel.poll_event(e);) {
    switch (e.kind) {
      case DisplayEventKind::stroke_completed: {
        StrokeResult r;
        r.stroke = e.stroke;
        r.typical_id = e.stroke < typical_ids.size() ? typical_ids[e.stroke] : 0;
        r.mean_deviation_m = e.mean_deviation_m;
        r.max_deviation_m = e.max_deviation_m;
        r.time_s = e.stroke_time_s;
        r.attempts = e.attempts;
        results.push_back(r);
        break;
      }
      case DisplayEventKind::stroke_abandoned:
        // Section 4.3.3: the trace of the unfinished stroke is cleared; a later attempt starts after it.
        ++abandoned;
        std::erase_if(segments, [&](const TraceSegment& s) {
          return s.stroke_index == e.stroke_index && s.first_tick <= e.tick;
        });
        segment_open = false;
        break;
      case DisplayEventKind::character_completed:
        break;
      case DisplayEventKind::trial_ended:
        ended = true;
        end = e.end;
        // The last ticks' points were pushed before this event: take them before the quiz's last verdicts.
        drain_trace(channel);
        if (quiz) {
          quiz->note_dropped(channel.dropped_trace_points());
          for (auto& event : quiz->finish()) quiz_unlogged.push_back(event);
        }
        break;
    }
  }
}

void TrialView::drain_trace(DisplayChannel& channel) {
  for (TracePoint p; channel.poll_trace(p);) {
    if (quiz) {
      for (auto& event : quiz->feed(p)) quiz_unlogged.push_back(event);
    }
    if (p.state != InteractionState::writing) {
      segment_open = false;
      continue;
    }
    const Vec2 point(p.hip_m.x, p.hip_m.y);
    if (!segment_open || segments.back().stroke_index != p.stroke_index) {
      segments.push_back(TraceSegment{p.stroke_index, p.tick, {point}});
      segment_open = true;
    } else if ((segments.back().points_m.back() - point).norm() >= kTraceStepM) {
      segments.back().points_m.push_back(point);
    }
  }
}

}  // namespace calligraphy::trainer
