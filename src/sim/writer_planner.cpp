#include "sim/writer_planner.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "sim/writer_attempt_program.hpp"

namespace calligraphy::writer_detail {

namespace {

constexpr double kVerdictLook_s = 0.1;  // after a stroke, how long past its visual delay the writer looks

}  // namespace

WriterPlanner::WriterPlanner(const Scene& scene, const WriterProfile& profile,
                             const WriterErrorInjector& injector, std::uint64_t plan_seed)
    : scene_(&scene), profile_(&profile), injector_(&injector), rng_(plan_seed) {
  std::size_t scene_stroke = 0;
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    character_offset_m_.push_back(injector.draw_character_offset(rng_));
    first_scene_stroke_.push_back(scene_stroke);
    const std::size_t n = scene.characters[c].strokes.size();
    for (const std::size_t k : injector.draw_stroke_order(n, rng_)) {
      plan_.push_back(PlannedStroke{c, k, scene_stroke + k, injector.draw_backwards(rng_)});
    }
    scene_stroke += n;
  }
  written_.assign(scene_stroke, false);
}

void WriterPlanner::see_display(std::size_t character, std::size_t stroke, bool finished) {
  seen_character_ = character;
  seen_stroke_ = stroke;
  seen_finished_ = finished;
  // The display has moved past the stroke being written: it was accepted, and what the writer feels
  // now (the paper outside the written stroke) is no refusal.
  if (!attempt_.accepted && seen_active() > attempt_.target.scene_stroke &&
      attempt_.display_at_start <= attempt_.target.scene_stroke) {
    attempt_.accepted = true;
    written_[attempt_.target.scene_stroke] = true;
  }
}

void WriterPlanner::touched_down(double time_s) {
  if (attempt_.ended) return;
  WriterAttempt& a = log_.attempts[attempt_.log_index];
  if (a.touch_down_s < 0.0) a.touch_down_s = time_s;
}

void WriterPlanner::reached_mid_lift() {
  if (!attempt_.ended) attempt_.mid_lift_reached = true;
}

void WriterPlanner::complete_attempt(double time_s) {
  if (attempt_.ended) return;
  written_[attempt_.target.scene_stroke] = true;  // by the writer's own account
  end_attempt(time_s, AttemptEnd::completed);
}

bool WriterPlanner::break_off(double time_s, AttemptEnd why, NextStroke then) {
  if (attempt_.ended) return false;
  end_attempt(time_s, why);
  next_ = then;
  redo_target_ = attempt_.target;
  return true;
}

void WriterPlanner::end_attempt(double time_s, AttemptEnd why) {
  WriterAttempt& a = log_.attempts[attempt_.log_index];
  a.end = why;
  a.end_s = time_s;
  attempt_.ended = true;
}

// The active stroke as last seen, counted over the scene (the stroke count once finished).
std::size_t WriterPlanner::seen_active() const {
  if (seen_finished_ || seen_character_ >= first_scene_stroke_.size()) return written_.size();
  return first_scene_stroke_[seen_character_] + seen_stroke_;
}

PlannedStroke WriterPlanner::hinted() const {
  PlannedStroke p;
  p.character = std::min(seen_character_, scene_->characters.size() - 1);
  p.stroke = std::min(seen_stroke_, scene_->characters[p.character].strokes.size() - 1);
  p.scene_stroke = first_scene_stroke_[p.character] + p.stroke;
  return p;
}

std::vector<Segment> WriterPlanner::next_program(double time_s, const Vec3& hold_m) {
  if (seen_finished_ || plan_.empty()) {
    done_ = true;
    return {};
  }
  if (log_.refusals > 0) take_strokes_before_hint();
  if (pause_for_verdict()) {
    return {make_segment(SegmentKind::pause, {hold_m}, 1.0, profile_->visual_delay_s + kVerdictLook_s)};
  }
  const std::optional<StrokeChoice> choice = choose_stroke();
  if (!choice) {  // its own plan written, and nothing ever refused
    done_ = true;
    return {};
  }
  next_ = NextStroke::plan;
  return start_attempt(choice->target, choice->follows_hint, time_s, hold_m);
}

// Once the display has refused a stroke the writer knows it keeps the order, and takes every stroke
// before the one it hints as written (also one the display took from a stroke the writer meant as
// another: a stroke out of order that passed the active stroke's feature planes).
void WriterPlanner::take_strokes_before_hint() {
  for (std::size_t k = 0; k < seen_active() && k < written_.size(); ++k) written_[k] = true;
}

// A stroke written whole where the display asked for it: look whether the display took it (it moves on)
// before going on; if it did not, write it again as the display shows it. True while the writer should
// pause to look.
bool WriterPlanner::pause_for_verdict() {
  const bool in_turn = !log_.attempts.empty() && attempt_.ended &&
                       log_.attempts[attempt_.log_index].end == AttemptEnd::completed &&
                       attempt_.display_at_start == attempt_.target.scene_stroke;
  if (moved_on_) {
    awaiting_verdict_ = false;  // moving on: no more looking whether the display took a stroke
  } else if (awaiting_verdict_) {
    awaiting_verdict_ = false;
    if (in_turn && !attempt_.accepted) {
      log_.attempts[attempt_.log_index].end = AttemptEnd::not_accepted;
      ++log_.not_accepted;
      written_[attempt_.target.scene_stroke] = false;
      next_ = NextStroke::hint;
    }
  } else if (in_turn && !attempt_.accepted) {
    awaiting_verdict_ = true;
    return true;
  }
  return false;
}

std::optional<StrokeChoice> WriterPlanner::choose_stroke() const {
  if (!moved_on_ && (next_ == NextStroke::hint || (next_ == NextStroke::plan && log_.refusals > 0))) {
    // After a refusal the writer has learnt that the display leads, and writes what it hints.
    return StrokeChoice{hinted(), true};
  }
  if (next_ == NextStroke::redo && !moved_on_) return StrokeChoice{redo_target_, false};
  const auto open = std::find_if(plan_.begin(), plan_.end(),
                                 [&](const PlannedStroke& p) { return !written_[p.scene_stroke]; });
  if (open == plan_.end()) return std::nullopt;
  return StrokeChoice{*open, false};
}

int WriterPlanner::attempt_number(std::size_t scene_stroke) const {
  int number = 1;
  for (const WriterAttempt& a : log_.attempts) {
    if (a.scene_stroke == scene_stroke) ++number;
  }
  return number;
}

// As an experimenter tells a learner stuck on a stroke: leave it and go on with the next one. The stroke
// stays as its last attempt left it; the writer counts it as written and writes the rest of its own plan
// (each further give-up marks one more stroke written, so this ends).
std::vector<Segment> WriterPlanner::give_up(const PlannedStroke& target, double time_s, const Vec3& hold_m) {
  log_.gave_up = true;
  ++log_.strokes_given_up;
  written_[target.scene_stroke] = true;
  moved_on_ = true;
  next_ = NextStroke::plan;
  return next_program(time_s, hold_m);
}

// Another stroke of the character, earlier in the reference order, not written yet by the writer's account.
bool WriterPlanner::earlier_stroke_open(const PlannedStroke& target) const {
  for (std::size_t k = 0; k < target.stroke; ++k) {
    if (!written_[first_scene_stroke_[target.character] + k]) return true;
  }
  return false;
}

void WriterPlanner::log_attempt(const PlannedStroke& target, int number, bool follows_hint, double time_s,
                                const AttemptErrors& errors) {
  WriterAttempt entry;
  entry.character = target.character;
  entry.stroke = target.stroke;
  entry.scene_stroke = target.scene_stroke;
  entry.reversed = target.reversed;
  entry.follows_hint = follows_hint;
  entry.attempt = number;
  entry.start_s = time_s;
  entry.outside_touch = errors.outside_touch;
  entry.out_of_order = earlier_stroke_open(target);
  // Every stroke has at least one leg, so a hesitation drawn always finds its place, and so does a lift.
  entry.hesitation = errors.hesitate;
  entry.mid_stroke_lift = errors.mid_stroke_lift;
  log_.attempts.push_back(entry);
}

std::vector<Segment> WriterPlanner::start_attempt(const PlannedStroke& planned, bool follows_hint,
                                                  double time_s, const Vec3& hold_m) {
  const int number = attempt_number(planned.scene_stroke);
  if (number > profile_->max_attempts_per_stroke) return give_up(planned, time_s, hold_m);
  // Each re-attempt is more careful: bias and error rates shrink by correction_per_attempt.
  const double care = std::pow(1.0 - profile_->correction_per_attempt, number - 1);
  PlannedStroke target = planned;
  target.reversed = planned.reversed && !follows_hint;  // a hinted stroke is written forwards
  const AttemptErrors errors = injector_->draw_attempt(care, rng_);
  log_attempt(target, number, follows_hint, time_s, errors);

  const PlacedCharacter& character = scene_->characters[target.character];
  AttemptIntent intent;
  intent.character = &character;
  intent.stroke = &character.strokes[target.stroke];
  intent.reversed = target.reversed;
  intent.care = care;
  intent.character_offset_m = character_offset_m_[target.character];
  intent.errors = errors;
  intent.from_m = hold_m;
  intent.paper_z_m = scene_->layout.paper_z_m;
  AttemptProgram plan = plan_attempt(intent, *profile_, *injector_, rng_);

  attempt_ = OpenAttempt{};
  attempt_.target = target;
  attempt_.log_index = log_.attempts.size() - 1;
  attempt_.ended = false;
  attempt_.display_at_start = seen_active();
  attempt_.start_m = plan.seen.front();
  attempt_.reference = std::move(plan.seen);
  return std::move(plan.program);
}

}  // namespace calligraphy::writer_detail
