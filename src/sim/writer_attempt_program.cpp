#include "sim/writer_attempt_program.hpp"

#include <algorithm>
#include <utility>

#include "calligraphy/model/polyline.hpp"
#include "sim/writer_random.hpp"

namespace calligraphy::writer_detail {

namespace {

// A corner of the seen stroke: a turn of more than 70 degrees summed within +-2.8 mm of arc (+-48 units of
// the data's 1024 box at 60 mm), the corner count that agreed with cnchar-order's fold counts on 97.4 % of
// hanzi-writer-data's strokes (docs/writer.md).
constexpr double kCornerWindow_m = 0.0028;
constexpr double kCornerTurn_deg = 70.0;
// The most of a stroke (or of its last leg) a lift short of the end leaves out: people's strokes measured
// against the medians (docs/stroke-acceptance.md) end short by at most 12 % of a short stroke.
constexpr double kMostShortShare = 0.12;

// The writer's copy of the seen stroke: its legs, biased, the last one ending where the pen lifts.
struct StrokeCopy {
  std::vector<Polyline> legs;  // at least one, each of at least two points [m]
  double beyond_m = 0.0;       // how far the last leg runs past the seen end [m] (< 0: short of it)
};

// What the writer sees: the stroke on the display (the data's median), in the direction it means to write
// it; it writes a copy of that, never the fitted elements.
Polyline seen_in_writing_direction(const PlacedStroke& stroke, bool reversed) {
  Polyline seen = seen_stroke(stroke);
  if (reversed) std::reverse(seen.begin(), seen.end());
  return seen;
}

// The seen stroke cut into legs at its corners (each corner cut inside by a draw), offset, scaled and
// jittered by the attempt's bias, its end moved to where the pen lifts (a draw).
StrokeCopy copy_stroke(const Polyline& seen, const AttemptIntent& intent, const WriterProfile& profile,
                       std::mt19937_64& rng) {
  const std::vector<std::size_t> corners = corner_vertices(seen, kCornerWindow_m, kCornerTurn_deg);
  std::vector<double> cuts;
  for (std::size_t k = 0; k < corners.size(); ++k) cuts.push_back(profile.corner_cut_m * uniform(rng));
  // Where the pen lifts, relative to the seen end; never more than a share of a short stroke.
  const double end_draw =
      std::max(-profile.end_short_m + (profile.end_short_m + profile.end_past_m) * uniform(rng),
               -kMostShortShare * polyline_length(seen)) +
      profile.follow_through_m;

  const double care = intent.care;
  const Vec2 centre = intent.character->bounding_box.center();
  const Vec2 offset = care * intent.character_offset_m;
  const double scale = 1.0 + care * profile.scale_error;
  const Vec2 jitter = intent.errors.jitter_m;
  const auto copy = [&](const Vec2& p) { return Vec2(centre + scale * (p - centre) + offset + jitter); };
  StrokeCopy result;
  result.legs = legs_through_corners(seen, corners, cuts);
  for (Polyline& leg : result.legs) {
    for (Vec2& p : leg) p = copy(p);
  }
  // The end: where the writer sees the stroke end on the display, whatever its copy says, plus the draw.
  Polyline& last = result.legs.back();
  const Vec2 direction = (last.back() - last[last.size() - 2]).normalized();
  const double short_m = direction.allFinite() ? (seen.back() - last.back()).dot(direction) : 0.0;
  result.beyond_m = std::max(short_m + end_draw, -kMostShortShare * polyline_length(last));
  last = with_end_moved(last, result.beyond_m);
  return result;
}

// Pen-up from `from` to above `start`, a hesitation there if placed so, a quick descent and the touch-down
// onto `start`, both aiming at the stroke's start.
void add_approach(std::vector<Segment>& program, const Vec3& from, const Vec3& start, bool hesitate,
                  const AttemptIntent& intent, const WriterProfile& profile) {
  const double up = intent.paper_z_m + profile.lift_height_m;
  const Vec3 above(start.x(), start.y(), up);
  program.push_back(make_segment(SegmentKind::travel,
                                 {from, Vec3(from.x(), from.y(), std::max(from.z(), up)), above},
                                 profile.travel_speed_m_s, kTravelMinimum_s));
  if (hesitate) program.push_back(WriterErrorInjector::hesitation(above, intent.errors));
  const Vec3 hover(start.x(), start.y(), intent.paper_z_m + kHoverHeight_m);
  program.push_back(make_segment(SegmentKind::descend, {above, hover}, profile.travel_speed_m_s, kDescend_s));
  program.back().aim_at_start = true;
  program.push_back(make_segment(SegmentKind::touch, {hover, start}, profile.travel_speed_m_s, kTouchDown_s));
  program.back().aim_at_start = true;
}

// The legs pen-down at `down_z_m`, each written up to the seen end and past it as follow-through, one of
// them lifted in the middle and a hesitation after one if the attempt's errors say so.
void add_legs(std::vector<Segment>& program, const StrokeCopy& copy, std::size_t hesitate_after,
              double down_z_m, const AttemptIntent& intent, const WriterProfile& profile,
              const WriterErrorInjector& injector) {
  const std::size_t leg_count = copy.legs.size();
  const std::size_t lifted = WriterErrorInjector::lifted_leg(intent.errors, leg_count);
  for (std::size_t k = 0; k < leg_count; ++k) {
    std::vector<Vec3> path;
    for (const Vec2& p : copy.legs[k]) path.push_back(on_plane(p, down_z_m));
    double proper_m = 0.0;  // the leg up to the seen end: past it is follow-through
    for (std::size_t i = 1; i < path.size(); ++i) proper_m += (path[i] - path[i - 1]).norm();
    if (k + 1 == leg_count) proper_m -= std::max(0.0, copy.beyond_m);
    if (k == lifted) {
      injector.add_lifted_leg(program, path, proper_m, intent.errors.lift_fraction, intent.paper_z_m);
    } else {
      program.push_back(make_write_segment(std::move(path), profile.writing_speed_m_s, proper_m));
    }
    if (k == hesitate_after)
      program.push_back(WriterErrorInjector::hesitation(program.back().path.back(), intent.errors));
  }
}

}  // namespace

AttemptProgram plan_attempt(const AttemptIntent& intent, const WriterProfile& profile,
                            const WriterErrorInjector& injector, std::mt19937_64& rng) {
  AttemptProgram plan;
  plan.seen = seen_in_writing_direction(*intent.stroke, intent.reversed);
  const StrokeCopy copy = copy_stroke(plan.seen, intent, profile, rng);
  const double up = intent.paper_z_m + profile.lift_height_m;
  const double down = intent.paper_z_m - profile.press_depth_m;
  const HesitationPlace hesitation = WriterErrorInjector::place_hesitation(intent.errors, copy.legs.size());

  std::vector<Segment>& program = plan.program;
  Vec3 from = intent.from_m;
  if (intent.errors.outside_touch)
    from = injector.add_outside_touch(program, *intent.character, from, intent.paper_z_m);
  add_approach(program, from, on_plane(copy.legs.front().front(), down), hesitation.before_stroke, intent,
               profile);
  add_legs(program, copy, hesitation.after_leg, down, intent, profile, injector);
  const Vec3 end = program.back().path.back();
  program.push_back(
      make_segment(SegmentKind::lift, {end, Vec3(end.x(), end.y(), up)}, profile.travel_speed_m_s, kLift_s));
  return plan;
}

}  // namespace calligraphy::writer_detail
