#include "trainer/trial_view.hpp"

#include <exception>

#include "calligraphy/analysis/stroke_matcher.hpp"

namespace calligraphy::trainer {
namespace {

// Points closer than this to the last one kept are not kept: the trace is drawn, and a pen-down path is
// judged as straight lines between its points, which at this spacing is the pen's path.
constexpr double kTraceStepM = 0.0001;

void append_thinned(std::vector<Vec2>& points, const Vec2& point) {
  if (points.empty() || (points.back() - point).norm() >= kTraceStepM) points.push_back(point);
}

}  // namespace

std::vector<int> typical_ids_of(const Character& character) {
  std::vector<int> ids;
  for (const Stroke& s : character.strokes) ids.push_back(s.typical_id);
  return ids;
}

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
        if (!quiz) feedback = stroke_written(e.stroke + 1, e.mean_deviation_m, acceptance);
        break;
      }
      case DisplayEventKind::stroke_abandoned: {
        // Section 4.3.3: the unfinished stroke is reloaded and a later attempt starts afresh. Its trace
        // leaves the written ones; the pen's whole path to the lift (from the touch-down, or from the
        // last stroke written without a lift), of which WS may have been the end only, stays, faded, as
        // the refused attempt, so that the learner sees what was wrong with it.
        ++abandoned;
        std::erase_if(segments, [&](const TraceSegment& s) {
          return s.stroke_index == e.stroke_index && s.first_tick <= e.tick;
        });
        segment_open = false;
        // A touch-down already drained after the lift starts the next attempt: this one is gone.
        if (touch_down_tick_ > e.tick) break;
        RefusedStroke attempt;
        attempt.stroke_index = e.stroke_index;
        attempt.character = e.character;
        attempt.stroke = e.stroke;
        attempt.refusal = e.refusal;
        attempt.points_m = pen_down_path_m_;
        refuse(std::move(attempt));
        break;
      }
      case DisplayEventKind::character_completed:
        break;
      case DisplayEventKind::stroke_assisted:
        // The trial demonstrated the stroke and credited it: drawn once over the paper, and said so.
        assisted = Shown{e.character, e.stroke, std::chrono::steady_clock::now()};
        feedback = stroke_assisted(e.stroke + 1);
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
  // After the events: the miss that brought the hint is said first, then the hint.
  follow_hint();
}

void TrialView::drain_trace(DisplayChannel& channel) {
  for (TracePoint p; channel.poll_trace(p);) {
    if (quiz) {
      for (auto& event : quiz->feed(p)) quiz_unlogged.push_back(event);
    }
    follow_pen(p);
    if (p.state != InteractionState::writing) {
      segment_open = false;
      continue;
    }
    const Vec2 point(p.hip_m.x, p.hip_m.y);
    if (!segment_open || segments.back().stroke_index != p.stroke_index) {
      segments.push_back(TraceSegment{p.stroke_index, p.tick, {point}});
      segment_open = true;
    } else {
      append_thinned(segments.back().points_m, point);
    }
  }
}

// The pen is on the paper in every state but SS (the renderer's contact test, with its hysteresis).
void TrialView::follow_pen(const TracePoint& point) {
  const bool down = point.state != InteractionState::separation;
  if (down && !pen_down_) {  // a touch-down: a new attempt, and the last refusal has been seen
    refused.reset();
    pen_down_reached_writing_ = false;
    touch_down_tick_ = point.tick;
    pen_down_stroke_index_ = point.stroke_index;
    pen_down_path_m_.clear();
  } else if (down && point.stroke_index != pen_down_stroke_index_) {
    // A stroke was written without a lift: what follows is an attempt at the next one. (It is not judged
    // from the path at the lift: the pen wrote in this pen-down, so what remains is its follow-through.)
    pen_down_stroke_index_ = point.stroke_index;
    pen_down_path_m_.clear();
  }
  if (down) {
    pen_down_reached_writing_ = pen_down_reached_writing_ || point.state == InteractionState::writing;
    append_thinned(pen_down_path_m_, Vec2(point.hip_m.x, point.hip_m.y));
  } else if (pen_down_) {
    judge_pen_down_path();
  }
  pen_down_ = down;
}

// A pen-down that never entered WS (it never came near the active stroke's start) gives the renderer no
// attempt to refuse: the stroke matcher reads its path as the renderer would and names what it wrote
// instead (a later stroke, the stroke backwards, ...). Off the servo thread: it allocates and takes up to
// a millisecond.
void TrialView::judge_pen_down_path() {
  if (quiz || scene == nullptr || pen_down_reached_writing_ || pen_down_path_m_.empty()) return;
  std::uint32_t first = 0;
  for (std::uint32_t c = 0; c < scene->characters.size(); ++c) {
    const PlacedCharacter& placed = scene->characters[c];
    const auto count = static_cast<std::uint32_t>(placed.strokes.size());
    if (pen_down_stroke_index_ < first + count) {
      const std::uint32_t stroke = pen_down_stroke_index_ - first;
      const StrokeMatch match =
          match_stroke(placed, stroke, pen_down_path_m_, scene->layout.start_radius_m, acceptance);
      if (match.accepted) return;  // written in the matcher's reading, yet not live: nothing to explain
      RefusedStroke attempt;
      attempt.stroke_index = pen_down_stroke_index_;
      attempt.character = c;
      attempt.stroke = stroke;
      attempt.refusal = match.refusal;
      attempt.judged_from_path = true;
      attempt.points_m = std::move(pen_down_path_m_);
      pen_down_path_m_.clear();
      refuse(std::move(attempt));
      return;
    }
    first += count;
  }
  // Past the last stroke: every stroke is written, nothing is asked.
}

void TrialView::refuse(RefusedStroke refused_stroke) {
  if (quiz) return;  // the quiz judges every stroke itself and shows its own verdicts
  refused = std::move(refused_stroke);
  ++refusals;
  // The learner's line: where the attempt started against the stroke's start, and which stroke it wrote
  // instead (the matcher's reading of the same path; off the servo thread).
  RefusedAttempt attempt;
  attempt.stroke_1based = refused->stroke + 1;
  attempt.refusal = refused->refusal;
  if (scene != nullptr && refused->character < scene->characters.size()) {
    const PlacedCharacter& placed = scene->characters[refused->character];
    attempt.start_radius_m = scene->layout.start_radius_m;
    if (refused->stroke < placed.strokes.size() && !refused->points_m.empty()) {
      attempt.start_offset_m = refused->points_m.front() - placed.strokes[refused->stroke].start();
      if (refused->refusal == StrokeRefusal::wrong_order || refused->refusal == StrokeRefusal::wrong_stroke) {
        try {
          const StrokeMatch match = match_stroke(placed, refused->stroke, refused->points_m,
                                                 scene->layout.start_radius_m, acceptance);
          if (match.refusal == StrokeRefusal::wrong_order || match.refusal == StrokeRefusal::wrong_stroke)
            attempt.written_instead_1based = match.matched_stroke + 1;
        } catch (const std::exception&) {  // a path the matcher cannot read: the line names no stroke
        }
      }
    }
  }
  feedback = stroke_refused(attempt);
}

// The trial shows the active stroke as a hint after misses (DisplaySnapshot::hint_shown): once per stroke.
void TrialView::follow_hint() {
  if (!snapshot.hint_shown || snapshot.finished || quiz) return;
  if (hint && hint->character == snapshot.character && hint->stroke == snapshot.stroke) return;
  hint = Shown{snapshot.character, snapshot.stroke, std::chrono::steady_clock::now()};
  feedback = stroke_hint(snapshot.stroke + 1);
}

}  // namespace calligraphy::trainer
