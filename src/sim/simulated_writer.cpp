#include "calligraphy/sim/simulated_writer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "model/polyline.hpp"
#include "sim/writer_program.hpp"
#include "sim/writer_stroke_path.hpp"

namespace calligraphy {

using writer_detail::make_segment;
using writer_detail::nearest_on_polyline;
using writer_detail::Polyline;
using writer_detail::Segment;
using writer_detail::SegmentKind;

namespace {

// Motion constants of the plan (docs/writer.md, "Movement"): assumed figures of an unhurried writer.
constexpr double kHoverHeight_m = 0.002;  // descent ends this far above the paper
constexpr double kTravelMinimum_s = 0.3;  // shortest pen-up move between strokes
constexpr double kDescend_s = 0.2;        // quick descent to just above the start
constexpr double kTouchDown_s = 0.3;      // gentle touch-down onto the paper
constexpr double kLift_s = 0.2;           // lift at the end of a stroke
constexpr double kVerdictLook_s = 0.1;    // after a stroke, how long past its visual delay the writer looks
constexpr double kMinimumLeg_s = 0.15;    // shortest leg of a stroke (between corners)
// A corner of the seen stroke: a turn of more than 70 degrees summed within +-2.8 mm of arc (+-48 units of
// the data's 1024 box at 60 mm), the corner count that agreed with cnchar-order's fold counts on 97.4 % of
// hanzi-writer-data's strokes (docs/writer.md).
constexpr double kCornerWindow_m = 0.0028;
constexpr double kCornerTurn_deg = 70.0;
// The most of a stroke (or of its last leg) a lift short of the end leaves out: people's strokes measured
// against the medians (docs/stroke-acceptance.md) end short by at most 12 % of a short stroke.
constexpr double kMostShortShare = 0.12;
constexpr double kNoiseUpdate_s = 1e-3;     // the hand's noise is redrawn every millisecond
constexpr double kVisionSample_s = 1e-3;    // resolution of the seen (delayed) pen and display
constexpr double kCorrectionDecay_s = 0.3;  // the visual correction fades while travelling pen-up
constexpr double kMidLiftHeight_m = 0.003;  // a lift in the middle of a stroke: how high,
constexpr double kMidLift_s = 0.12;         // how long up and down,
constexpr double kMidLiftHold_s = 0.1;      // and how long the pen stays up
constexpr double kStrayDistance_m = 0.004;  // a touch outside the box lands this far outside it
constexpr double kStrayLength_m = 0.004;    // and slides this far along it

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

// Two independent standard normal draws: Box-Muller on our own uniform draws, so results do not depend on
// the standard library's distributions.
Vec2 gaussian_pair(std::mt19937_64& rng) {
  const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53;
  const double u2 = uniform(rng);
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  return radius * Vec2(std::cos(angle), std::sin(angle));
}

// SplitMix64 (Steele, Lea & Flood 2014): independent seeds for the plan and the hand's noise.
std::uint64_t split_seed(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Vec3 on_plane(const Vec2& p, double z) { return Vec3(p.x(), p.y(), z); }

// The error vector shortened by the tolerance: no correction within it, continuous at its edge.
Vec2 beyond_tolerance(const Vec2& error, double tolerance) {
  const double n = error.norm();
  return n > tolerance ? Vec2(error * (1.0 - tolerance / n)) : Vec2(Vec2::Zero());
}

}  // namespace

struct SimulatedWriter::State {
  struct VisionSample {
    double time_s = 0.0;
    Vec2 pen = Vec2::Zero();
    std::size_t character = 0;
    std::size_t stroke = 0;
    bool finished = false;
    bool abandoned = false;
    std::uint64_t sequence = 0;
  };
  struct Attempt {
    PlannedStroke target;
    std::size_t log_index = 0;
    std::vector<Vec2> reference;  // the true stroke as a polyline, for what the writer sees
    Vec2 start_m = Vec2::Zero();  // the true start in the writing direction
    bool mid_lift_reached = false;
    bool ended = true;
    std::size_t display_at_start = 0;  // the active stroke (scene index) the writer saw when it set off
    bool accepted = false;             // the writer has seen the display move past this stroke
  };
  enum class Next { plan, hint, redo };

  const Scene* scene;
  WriterProfile profile;
  std::mt19937_64 plan_rng;
  std::mt19937_64 noise_rng;
  std::vector<Vec2> character_offset_m;
  std::vector<std::size_t> first_scene_stroke;
  std::vector<PlannedStroke> plan;
  std::vector<bool> written;
  WriterLog log;

  // Motion program and its phase.
  std::vector<Segment> program;
  std::size_t current = 0;
  double phase = 0.0;
  double rate_per_s = 0.0;
  Vec3 hold = Vec3::Zero();
  bool started = false;
  double observed_s = 0.0;

  // Closed loop: visual correction of x_d and pace.
  Vec2 correction_m = Vec2::Zero();
  Vec2 correction_rate_m_s = Vec2::Zero();
  double seen_error_m = 0.0;
  double speed_factor = 1.0;
  double next_vision_s = 0.0;
  double resisted_s = 0.0;

  // What the writer sees, late: a ring of samples every kVisionSample_s.
  std::vector<VisionSample> ring;
  std::size_t ring_next = 0;
  std::size_t ring_count = 0;
  std::uint64_t sequence = 0;
  std::uint64_t processed_sequence = 0;
  double last_stored_s = -std::numeric_limits<double>::infinity();
  bool pending_abandon = false;
  std::size_t seen_character = 0;
  std::size_t seen_stroke = 0;
  bool seen_finished = false;

  Attempt attempt;
  Next next = Next::plan;
  bool awaiting_verdict = false;  // pausing after a stroke to see whether the display took it
  PlannedStroke redo_target;
  bool done = false;
  // Past its last attempt at a stroke the writer moved on (docs/writer.md, "Give-up and retries"): it writes
  // the rest of its own plan and no longer waits for, or yields to, the display.
  bool moved_on = false;

  // The motor command issued at the last observation: where the plan puts the hand and how fast it moves
  // there; the hand follows its first-order hold until the next observation.
  writer_detail::Motion command;
  double command_s = 0.0;

  Vec3 noise_n = Vec3::Zero();
  double noise_time_s = -1.0;
  Vec2 tremor_cos = Vec2::Ones();  // the cosines and sines of the tremor's phases on x and y
  Vec2 tremor_sin = Vec2::Zero();
  Vec3 tremor_n = Vec3::Zero();

  State(const Scene& s, const WriterProfile& p, std::uint64_t seed);
  [[nodiscard]] writer_detail::Motion desired(double time_s) const;
  [[nodiscard]] Vec3 planned_now() const;
  void update_rate();
  void issue_command(double time_s);
  void advance(double dt, double time_s);
  void store_seen(const RenderOutput& output, const DeviceState& pen);
  [[nodiscard]] const VisionSample& stored(std::size_t k) const;  // the k-th newest, k in [1, ring_count]
  [[nodiscard]] const VisionSample* seen_at(double time_s) const;
  void look(double time_s);
  void feel(const RenderOutput& output, double dt, double time_s);
  void pace(double dt);
  void break_off(double time_s, AttemptEnd why, Next then);
  void end_attempt(double time_s, AttemptEnd why);
  void choose_next(double time_s);
  [[nodiscard]] PlannedStroke hinted() const;
  [[nodiscard]] std::size_t seen_active() const;
  void start_attempt(const PlannedStroke& target, bool follows_hint, double time_s);
  Vec3 add_stray_touch(const PlacedCharacter& character, const Vec3& from);
};

SimulatedWriter::State::State(const Scene& s, const WriterProfile& p, std::uint64_t seed)
    : scene(&s), profile(p) {
  profile.validate();
  std::uint64_t seeds = seed;
  plan_rng.seed(split_seed(seeds));
  noise_rng.seed(split_seed(seeds));
  std::size_t scene_stroke = 0;
  for (std::size_t c = 0; c < s.characters.size(); ++c) {
    const double angle = 2.0 * std::numbers::pi * uniform(plan_rng);
    character_offset_m.push_back(profile.bias_offset_m * Vec2(std::cos(angle), std::sin(angle)));
    first_scene_stroke.push_back(scene_stroke);
    // The writer's own order: each stroke may swap with the next (an order error), and each may be
    // meant backwards (a direction error).
    const std::size_t n = s.characters[c].strokes.size();
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i) order[i] = i;
    for (std::size_t i = 0; i + 1 < n;) {
      if (uniform(plan_rng) < profile.order_error_probability) {
        std::swap(order[i], order[i + 1]);
        i += 2;
      } else {
        i += 1;
      }
    }
    for (const std::size_t k : order) {
      plan.push_back(
          PlannedStroke{c, k, scene_stroke + k, uniform(plan_rng) < profile.backwards_probability});
    }
    scene_stroke += n;
  }
  written.assign(scene_stroke, false);
  const double tremor_phase_x = 2.0 * std::numbers::pi * uniform(noise_rng);
  const double tremor_phase_y = 2.0 * std::numbers::pi * uniform(noise_rng);
  tremor_cos = Vec2(std::cos(tremor_phase_x), std::cos(tremor_phase_y));
  tremor_sin = Vec2(std::sin(tremor_phase_x), std::sin(tremor_phase_y));
  ring.resize(static_cast<std::size_t>(std::ceil(profile.visual_delay_s / kVisionSample_s)) + 16);
}

Vec3 SimulatedWriter::State::planned_now() const {
  return current < program.size() ? program[current].at_phase(phase) : hold;
}

// The hand's target: the program's point now, moved by the correction, and its exact time derivative (the
// hand's damping acts on the error in velocity, Flash & Hogan's minimum-jerk speed profile included).
writer_detail::Motion SimulatedWriter::State::desired(double time_s) const {
  const double ahead = time_s - observed_s;
  writer_detail::Motion motion{hold, Vec3::Zero()};
  if (current < program.size()) {
    const double unclamped = phase + rate_per_s * ahead;
    motion = program[current].motion_at_phase(std::clamp(unclamped, 0.0, 1.0), rate_per_s);
  }
  const Vec2 c = correction_m + correction_rate_m_s * ahead;
  motion.position_m += Vec3(c.x(), c.y(), 0.0);
  motion.velocity_m_s += Vec3(correction_rate_m_s.x(), correction_rate_m_s.y(), 0.0);
  return motion;
}

void SimulatedWriter::State::update_rate() {
  if (current >= program.size()) {
    rate_per_s = 0.0;
    return;
  }
  const Segment& s = program[current];
  rate_per_s = (s.steered ? speed_factor : 1.0) / s.duration_s;
}

void SimulatedWriter::State::advance(double dt, double time_s) {
  if (program.empty()) return;
  phase += rate_per_s * dt;
  while (current < program.size() && phase >= 1.0) {
    const double beyond_s = rate_per_s > 0.0 ? (phase - 1.0) / rate_per_s : 0.0;
    hold = program[current].path.back();
    ++current;
    phase = 0.0;
    resisted_s = 0.0;
    if (current >= program.size()) break;
    const Segment& s = program[current];
    if (!attempt.ended) {
      WriterAttempt& a = log.attempts[attempt.log_index];
      if (s.kind == SegmentKind::write && a.touch_down_s < 0.0) a.touch_down_s = time_s - beyond_s;
      if (s.mid_stroke) attempt.mid_lift_reached = true;
    }
    update_rate();
    phase = rate_per_s * beyond_s;
  }
  if (current >= program.size()) {
    program.clear();
    current = 0;
    phase = 0.0;
    if (!attempt.ended) {
      written[attempt.target.scene_stroke] = true;  // by the writer's own account
      end_attempt(time_s, AttemptEnd::completed);
    }
  }
}

void SimulatedWriter::State::store_seen(const RenderOutput& output, const DeviceState& pen) {
  pending_abandon = pending_abandon || output.stroke_abandoned;
  if (pen.time_s - last_stored_s < kVisionSample_s * (1.0 - 1e-9)) return;
  VisionSample& v = ring[ring_next];
  v.time_s = pen.time_s;
  v.pen = pen.position_m.head<2>();
  v.character = output.character;
  v.stroke = output.stroke;
  v.finished = output.finished;
  v.abandoned = pending_abandon;
  v.sequence = ++sequence;
  pending_abandon = false;
  last_stored_s = pen.time_s;
  ring_next = (ring_next + 1) % ring.size();
  ring_count = std::min(ring_count + 1, ring.size());
}

const SimulatedWriter::State::VisionSample& SimulatedWriter::State::stored(std::size_t k) const {
  return ring[ring_next >= k ? ring_next - k : ring_next + ring.size() - k];
}

const SimulatedWriter::State::VisionSample* SimulatedWriter::State::seen_at(double time_s) const {
  if (ring_count == 0) return nullptr;
  // The newest sample at or before time_s: the samples' times fall with k, so bisect for the least such k.
  std::size_t low = 1;
  std::size_t high = ring_count;
  if (!(stored(high).time_s <= time_s + 1e-12)) return &stored(high);  // nothing that old yet: the earliest
  while (low < high) {
    const std::size_t k = low + (high - low) / 2;
    if (stored(k).time_s <= time_s + 1e-12) {
      high = k;
    } else {
      low = k + 1;
    }
  }
  return &stored(low);
}

// Vision, every vision_period_s: the pen and the display as they were visual_delay_s ago.
void SimulatedWriter::State::look(double time_s) {
  const VisionSample* seen = seen_at(time_s - profile.visual_delay_s);
  if (seen == nullptr) return;
  // A stroke cleared after a lift in the middle of it: write it again. The samples seen since the last look,
  // oldest first; the k-th newest has sequence number `sequence` + 1 - k.
  const std::size_t newest_unseen = std::min<std::uint64_t>(ring_count, sequence - processed_sequence);
  for (std::size_t k = newest_unseen; k >= 1 && sequence + 1 - k <= seen->sequence; --k) {
    const VisionSample& v = stored(k);
    if (v.abandoned && !attempt.ended && attempt.mid_lift_reached) {
      break_off(time_s, AttemptEnd::interrupted, Next::redo);
    }
  }
  processed_sequence = std::max(processed_sequence, seen->sequence);
  seen_character = seen->character;
  seen_stroke = seen->stroke;
  seen_finished = seen->finished;
  // The display has moved past the stroke being written: it was accepted, and what the writer feels
  // now (the paper outside the written stroke) is no refusal.
  if (!attempt.accepted && seen_active() > attempt.target.scene_stroke &&
      attempt.display_at_start <= attempt.target.scene_stroke) {
    attempt.accepted = true;
    written[attempt.target.scene_stroke] = true;
  }

  Vec2 error = Vec2::Zero();
  bool writing = false;
  bool travelling = true;
  if (current < program.size() && !attempt.ended) {
    const Segment& s = program[current];
    travelling = s.kind == SegmentKind::travel;
    if (s.aim_at_start) {
      error = attempt.start_m - seen->pen;
    } else if (s.kind == SegmentKind::write) {
      // Only the error across the stroke: along it the writer is where its pace puts it.
      const writer_detail::PolylineFoot foot = nearest_on_polyline(attempt.reference, seen->pen);
      const Vec2 e = foot.foot - seen->pen;
      error = e - e.dot(foot.direction) * foot.direction;
      writing = true;
    }
  }
  if (travelling) {
    correction_rate_m_s = -correction_m / kCorrectionDecay_s;
  } else {
    correction_rate_m_s = profile.correction_rate_per_s * beyond_tolerance(error, profile.error_tolerance_m);
  }
  if (writing) {
    const double blend = 1.0 - std::exp(-profile.vision_period_s / profile.error_filter_s);
    seen_error_m += blend * (error.norm() - seen_error_m);
  }
}

// Touch: a force against the intended motion, beyond the paper's usual drag, for the reaction time
// means the display refuses the stroke (the resistance of Fig. 4, the off-stroke resistance).
void SimulatedWriter::State::feel(const RenderOutput& output, double dt, double time_s) {
  if (attempt.ended || current >= program.size()) {
    resisted_s = 0.0;
    return;
  }
  const Segment& s = program[current];
  const double along = s.length_m() * Segment::minimum_jerk(phase);
  if (s.kind != SegmentKind::write || along >= s.follow_from_m || attempt.accepted) {
    resisted_s = 0.0;
    return;
  }
  const Vec2 intended = s.direction_at_arc(along);
  const Vec3& f = output.force_n;
  const double against = -f.head<2>().dot(intended) - profile.expected_drag_ratio * std::max(f.z(), 0.0);
  resisted_s = (!intended.isZero() && against > profile.resistance_threshold_n) ? resisted_s + dt : 0.0;
  if (resisted_s >= profile.reaction_time_s && !moved_on) {
    ++log.refusals;
    break_off(time_s, AttemptEnd::refused, Next::hint);
  }
}

// Steering law, local form v = W_free / tau with W_free = W - 2 |e| (Accot & Zhai 1997), tau = W / v0.
void SimulatedWriter::State::pace(double dt) {
  const double target =
      std::clamp(1.0 - 2.0 * seen_error_m / profile.steering_width_m, profile.min_speed_fraction, 1.0);
  speed_factor += (1.0 - std::exp(-dt / profile.speed_time_constant_s)) * (target - speed_factor);
}

void SimulatedWriter::State::end_attempt(double time_s, AttemptEnd why) {
  WriterAttempt& a = log.attempts[attempt.log_index];
  a.end = why;
  a.end_s = time_s;
  attempt.ended = true;
}

void SimulatedWriter::State::break_off(double time_s, AttemptEnd why, Next then) {
  if (attempt.ended) return;
  end_attempt(time_s, why);
  const Vec3 here = planned_now();
  const double up = scene->layout.paper_z_m + profile.lift_height_m;
  program.clear();
  program.push_back(make_segment(SegmentKind::lift, {here, Vec3(here.x(), here.y(), std::max(here.z(), up))},
                                 profile.travel_speed_m_s, kLift_s));
  current = 0;
  phase = 0.0;
  resisted_s = 0.0;
  next = then;
  redo_target = attempt.target;
  update_rate();
}

// The active stroke as last seen, counted over the scene (the stroke count once finished).
std::size_t SimulatedWriter::State::seen_active() const {
  if (seen_finished || seen_character >= first_scene_stroke.size()) return written.size();
  return first_scene_stroke[seen_character] + seen_stroke;
}

PlannedStroke SimulatedWriter::State::hinted() const {
  PlannedStroke p;
  p.character = std::min(seen_character, scene->characters.size() - 1);
  p.stroke = std::min(seen_stroke, scene->characters[p.character].strokes.size() - 1);
  p.scene_stroke = first_scene_stroke[p.character] + p.stroke;
  return p;
}

void SimulatedWriter::State::choose_next(double time_s) {
  if (seen_finished || plan.empty()) {
    done = true;
    return;
  }
  // Once the display has refused a stroke the writer knows it keeps the order, and takes every stroke
  // before the one it hints as written (also one the display took from a stroke the writer meant as
  // another: a stroke out of order that passed the active stroke's feature planes).
  if (log.refusals > 0) {
    for (std::size_t k = 0; k < seen_active() && k < written.size(); ++k) written[k] = true;
  }
  // A stroke written whole where the display asked for it: look whether the display took it (it moves
  // on) before going on; if it did not, write it again as the display shows it.
  const bool in_turn = !log.attempts.empty() && attempt.ended &&
                       log.attempts[attempt.log_index].end == AttemptEnd::completed &&
                       attempt.display_at_start == attempt.target.scene_stroke;
  if (moved_on) {
    awaiting_verdict = false;  // moving on: no more looking whether the display took a stroke
  } else if (awaiting_verdict) {
    awaiting_verdict = false;
    if (in_turn && !attempt.accepted) {
      log.attempts[attempt.log_index].end = AttemptEnd::not_accepted;
      ++log.not_accepted;
      written[attempt.target.scene_stroke] = false;
      next = Next::hint;
    }
  } else if (in_turn && !attempt.accepted) {
    awaiting_verdict = true;
    program.push_back(make_segment(SegmentKind::pause, {hold}, 1.0, profile.visual_delay_s + kVerdictLook_s));
    current = 0;
    phase = 0.0;
    return;
  }
  PlannedStroke target;
  bool follows_hint = false;
  if (!moved_on && (next == Next::hint || (next == Next::plan && log.refusals > 0))) {
    // After a refusal the writer has learnt that the display leads, and writes what it hints.
    target = hinted();
    follows_hint = true;
  } else if (next == Next::redo && !moved_on) {
    target = redo_target;
  } else {
    const auto open = std::find_if(plan.begin(), plan.end(),
                                   [&](const PlannedStroke& p) { return !written[p.scene_stroke]; });
    if (open == plan.end()) {  // its own plan written, and nothing ever refused
      done = true;
      return;
    }
    target = *open;
  }
  next = Next::plan;
  start_attempt(target, follows_hint, time_s);
}

Vec3 SimulatedWriter::State::add_stray_touch(const PlacedCharacter& character, const Vec3& from) {
  const Eigen::AlignedBox2d& box = character.bounding_box;
  const Vec2 p = from.head<2>();
  const Vec2 lo = box.min();
  const Vec2 hi = box.max();
  const double y = std::clamp(p.y(), lo.y(), hi.y());
  const double x = std::clamp(p.x(), lo.x(), hi.x());
  const Vec2 candidates[4] = {Vec2(lo.x() - kStrayDistance_m, y), Vec2(hi.x() + kStrayDistance_m, y),
                              Vec2(x, lo.y() - kStrayDistance_m), Vec2(x, hi.y() + kStrayDistance_m)};
  std::size_t best = 0;
  for (std::size_t i = 1; i < 4; ++i) {
    if ((candidates[i] - p).norm() < (candidates[best] - p).norm()) best = i;
  }
  const Vec2 touch = candidates[best];
  const Vec2 centre = box.center();
  const Vec2 slide = best < 2 ? Vec2(0.0, centre.y() > touch.y() ? 1.0 : -1.0)
                              : Vec2(centre.x() > touch.x() ? 1.0 : -1.0, 0.0);
  const Vec2 end = touch + kStrayLength_m * slide;
  const double z0 = scene->layout.paper_z_m;
  const double up = z0 + profile.lift_height_m;
  const double down = z0 - 0.5 * profile.press_depth_m;
  program.push_back(make_segment(SegmentKind::travel,
                                 {from, Vec3(p.x(), p.y(), std::max(from.z(), up)), on_plane(touch, up)},
                                 profile.travel_speed_m_s, kTravelMinimum_s));
  program.push_back(make_segment(SegmentKind::touch, {on_plane(touch, up), on_plane(touch, down)},
                                 profile.travel_speed_m_s, kTouchDown_s));
  program.push_back(make_segment(SegmentKind::stray, {on_plane(touch, down), on_plane(end, down)},
                                 profile.writing_speed_m_s, kMinimumLeg_s));
  program.push_back(make_segment(SegmentKind::lift, {on_plane(end, down), on_plane(end, up)},
                                 profile.travel_speed_m_s, kLift_s));
  return on_plane(end, up);
}

void SimulatedWriter::State::start_attempt(const PlannedStroke& target, bool follows_hint, double time_s) {
  int number = 1;
  for (const WriterAttempt& a : log.attempts) {
    if (a.scene_stroke == target.scene_stroke) ++number;
  }
  if (number > profile.max_attempts_per_stroke) {
    // As an experimenter tells a learner stuck on a stroke: leave it and go on with the next one. The
    // stroke stays as its last attempt left it; the writer counts it as written and writes the rest of its
    // own plan (each further give-up marks one more stroke written, so this ends).
    log.gave_up = true;
    ++log.strokes_given_up;
    written[target.scene_stroke] = true;
    moved_on = true;
    next = Next::plan;
    choose_next(time_s);
    return;
  }
  // Each re-attempt is more careful: bias and error rates shrink by correction_per_attempt.
  const double care = std::pow(1.0 - profile.correction_per_attempt, number - 1);
  const PlacedCharacter& character = scene->characters[target.character];
  const PlacedStroke& ref = character.strokes[target.stroke];
  const bool reversed = target.reversed && !follows_hint;

  // Draws in a fixed order, so that the plan does not depend on the servo rate.
  const bool outside = uniform(plan_rng) < care * profile.outside_touch_probability;
  const bool hesitate = uniform(plan_rng) < care * profile.hesitation_probability;
  const double hesitation_where = uniform(plan_rng);
  const double hesitation_length_s = profile.hesitation_s * (0.5 + uniform(plan_rng));
  const bool lift = uniform(plan_rng) < care * profile.mid_stroke_lift_probability;
  const double lift_where = uniform(plan_rng);
  const double lift_fraction = 0.3 + 0.4 * uniform(plan_rng);
  const Vec2 jitter = care * profile.stroke_jitter_m * gaussian_pair(plan_rng);

  WriterAttempt entry;
  entry.character = target.character;
  entry.stroke = target.stroke;
  entry.scene_stroke = target.scene_stroke;
  entry.reversed = reversed;
  entry.follows_hint = follows_hint;
  entry.attempt = number;
  entry.start_s = time_s;
  entry.outside_touch = outside;
  for (std::size_t k = 0; k < target.stroke; ++k) {
    if (!written[first_scene_stroke[target.character] + k]) entry.out_of_order = true;
  }
  log.attempts.push_back(entry);
  attempt = Attempt{};
  attempt.target = target;
  attempt.target.reversed = reversed;
  attempt.log_index = log.attempts.size() - 1;
  attempt.ended = false;
  attempt.start_m = reversed ? ref.end() : ref.start();
  attempt.display_at_start = seen_active();

  // What the writer sees: the stroke on the display (the data's median), in the direction it means to
  // write it, cut into legs at its corners; it writes a copy of that, biased, never the fitted elements.
  Polyline seen = writer_detail::seen_stroke(ref);
  if (reversed) std::reverse(seen.begin(), seen.end());
  attempt.reference = seen;
  attempt.start_m = seen.front();
  const std::vector<std::size_t> corners =
      writer_detail::corner_vertices(seen, kCornerWindow_m, kCornerTurn_deg);
  std::vector<double> cuts;
  for (std::size_t k = 0; k < corners.size(); ++k) cuts.push_back(profile.corner_cut_m * uniform(plan_rng));
  // Where the pen lifts, relative to the seen end; never more than a share of a short stroke.
  const double end_draw =
      std::max(-profile.end_short_m + (profile.end_short_m + profile.end_past_m) * uniform(plan_rng),
               -kMostShortShare * polyline_length(seen)) +
      profile.follow_through_m;

  const Vec2 centre = character.bounding_box.center();
  const Vec2 offset = care * character_offset_m[target.character];
  const double scale = 1.0 + care * profile.scale_error;
  const auto copy = [&](const Vec2& p) { return Vec2(centre + scale * (p - centre) + offset + jitter); };
  std::vector<Polyline> legs = writer_detail::legs_through_corners(seen, corners, cuts);
  for (Polyline& leg : legs) {
    for (Vec2& p : leg) p = copy(p);
  }
  // The end: where the writer sees the stroke end on the display, whatever its copy says, plus the draw.
  double beyond_m = 0.0;
  {
    Polyline& last = legs.back();
    const Vec2 direction = (last.back() - last[last.size() - 2]).normalized();
    const double short_m = direction.allFinite() ? (seen.back() - last.back()).dot(direction) : 0.0;
    beyond_m = std::max(short_m + end_draw, -kMostShortShare * polyline_length(last));
    last = writer_detail::with_end_moved(last, beyond_m);
  }
  const double z0 = scene->layout.paper_z_m;
  const double up = z0 + profile.lift_height_m;
  const double down = z0 - profile.press_depth_m;
  const std::size_t leg_count = legs.size();

  program.clear();
  current = 0;
  phase = 0.0;
  Vec3 from = hold;
  if (outside) from = add_stray_touch(character, from);
  const Vec3 start = on_plane(legs.front().front(), down);
  const Vec3 above(start.x(), start.y(), up);
  program.push_back(make_segment(SegmentKind::travel,
                                 {from, Vec3(from.x(), from.y(), std::max(from.z(), up)), above},
                                 profile.travel_speed_m_s, kTravelMinimum_s));
  const bool hesitate_before = hesitate && (leg_count < 2 || hesitation_where < 0.5);
  const std::size_t hesitate_after =
      hesitate && !hesitate_before
          ? std::min(leg_count - 2, static_cast<std::size_t>(2.0 * (hesitation_where - 0.5) *
                                                             static_cast<double>(leg_count - 1)))
          : leg_count;
  if (hesitate_before) {
    program.push_back(make_segment(SegmentKind::pause, {above}, 1.0, hesitation_length_s));
    log.attempts.back().hesitation = true;
  }
  const Vec3 hover(start.x(), start.y(), z0 + kHoverHeight_m);
  program.push_back(make_segment(SegmentKind::descend, {above, hover}, profile.travel_speed_m_s, kDescend_s));
  program.back().aim_at_start = true;
  program.push_back(make_segment(SegmentKind::touch, {hover, start}, profile.travel_speed_m_s, kTouchDown_s));
  program.back().aim_at_start = true;

  const std::size_t lifted_leg =
      lift ? std::min(leg_count - 1, static_cast<std::size_t>(lift_where * static_cast<double>(leg_count)))
           : leg_count;
  for (std::size_t k = 0; k < leg_count; ++k) {
    std::vector<Vec3> path;
    for (const Vec2& p : legs[k]) path.push_back(on_plane(p, down));
    double proper_m = 0.0;  // the leg up to the seen end: past it is follow-through
    for (std::size_t i = 1; i < path.size(); ++i) proper_m += (path[i] - path[i - 1]).norm();
    if (k + 1 == leg_count) proper_m -= std::max(0.0, beyond_m);
    if (k == lifted_leg) {
      // Split at lift_fraction of the leg: write, lift, hold, touch down again, write on.
      const double split_m = lift_fraction * proper_m;
      std::vector<Vec3> first{path.front()};
      std::vector<Vec3> second;
      double run_m = 0.0;
      std::size_t i = 1;
      for (; i < path.size(); ++i) {
        const double step = (path[i] - path[i - 1]).norm();
        if (run_m + step >= split_m && step > 0.0) {
          const Vec3 split = path[i - 1] + ((split_m - run_m) / step) * (path[i] - path[i - 1]);
          first.push_back(split);
          second.push_back(split);
          break;
        }
        run_m += step;
        first.push_back(path[i]);
      }
      for (; i < path.size(); ++i) second.push_back(path[i]);
      if (second.empty()) second.push_back(first.back());
      const Vec3 split = first.back();
      const Vec3 raised(split.x(), split.y(), z0 + kMidLiftHeight_m);
      Segment a =
          make_segment(SegmentKind::write, std::move(first), profile.writing_speed_m_s, kMinimumLeg_s);
      a.steered = true;
      program.push_back(std::move(a));
      program.push_back(
          make_segment(SegmentKind::lift, {split, raised}, profile.travel_speed_m_s, kMidLift_s));
      program.back().mid_stroke = true;
      program.push_back(make_segment(SegmentKind::pause, {raised}, 1.0, kMidLiftHold_s));
      program.back().mid_stroke = true;
      program.push_back(
          make_segment(SegmentKind::touch, {raised, split}, profile.travel_speed_m_s, kMidLift_s));
      program.back().mid_stroke = true;
      Segment b =
          make_segment(SegmentKind::write, std::move(second), profile.writing_speed_m_s, kMinimumLeg_s);
      b.steered = true;
      b.follow_from_m = std::max(0.0, proper_m - split_m);
      program.push_back(std::move(b));
      log.attempts.back().mid_stroke_lift = true;
    } else {
      Segment w = make_segment(SegmentKind::write, std::move(path), profile.writing_speed_m_s, kMinimumLeg_s);
      w.steered = true;
      w.follow_from_m = proper_m;
      program.push_back(std::move(w));
    }
    if (k == hesitate_after) {
      program.push_back(
          make_segment(SegmentKind::pause, {program.back().path.back()}, 1.0, hesitation_length_s));
      log.attempts.back().hesitation = true;
    }
  }
  const Vec3 end = program.back().path.back();
  program.push_back(
      make_segment(SegmentKind::lift, {end, Vec3(end.x(), end.y(), up)}, profile.travel_speed_m_s, kLift_s));
  update_rate();
}

SimulatedWriter::SimulatedWriter(const Scene& scene, const WriterProfile& profile, std::uint64_t seed)
    : state_(std::make_unique<State>(scene, profile, seed)) {}
SimulatedWriter::~SimulatedWriter() = default;
SimulatedWriter::SimulatedWriter(SimulatedWriter&&) noexcept = default;
SimulatedWriter& SimulatedWriter::operator=(SimulatedWriter&&) noexcept = default;

bool SimulatedWriter::done() const noexcept { return state_->done; }
const WriterLog& SimulatedWriter::log() const noexcept { return state_->log; }
const std::vector<PlannedStroke>& SimulatedWriter::plan() const noexcept { return state_->plan; }
const WriterProfile& SimulatedWriter::profile() const noexcept { return state_->profile; }

Vec3 SimulatedWriter::target(double time_s) const {
  const State& s = *state_;
  return s.started ? Vec3(s.command.position_m + (time_s - s.command_s) * s.command.velocity_m_s) : s.hold;
}

void SimulatedWriter::observe(const RenderOutput& output, const DeviceState& pen) {
  State& s = *state_;
  const double time_s = pen.time_s;
  if (!s.started) {
    s.started = true;
    s.observed_s = time_s;
    s.hold = pen.position_m;
    s.next_vision_s = time_s;
  }
  const double dt = std::max(0.0, time_s - s.observed_s);
  s.correction_m += s.correction_rate_m_s * dt;
  s.advance(dt, time_s);
  s.observed_s = time_s;
  s.store_seen(output, pen);
  if (s.done) {
    s.issue_command(time_s);
    return;
  }
  s.feel(output, dt, time_s);
  while (time_s >= s.next_vision_s) {
    s.look(time_s);
    s.next_vision_s += s.profile.vision_period_s;
  }
  s.pace(dt);
  if (s.program.empty()) s.choose_next(time_s);
  s.update_rate();
  s.issue_command(time_s);
}

void SimulatedWriter::State::issue_command(double time_s) {
  command = desired(time_s);
  command_s = time_s;
}

Vec3 SimulatedWriter::hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) {
  State& s = *state_;
  const WriterProfile& p = s.profile;
  if (!s.started) s.hold = position_m;  // before the first observation the hand holds still
  const Vec3 x_d = target(time_s);
  const Vec3 v_d = s.started ? s.command.velocity_m_s : Vec3(Vec3::Zero());
  const Vec3 force =
      p.hand_stiffness_n_per_m * (x_d - position_m) + p.hand_damping_n_s_per_m * (v_d - velocity_m_s);
  // Signal-dependent noise (Harris & Wolpert 1998) and the physiological tremor, in plane, both held for
  // kNoiseUpdate_s: the 8-12 Hz tremor is smooth on that scale, and a sine per physics substep cost a
  // tenth of a simulated trial.
  if (time_s - s.noise_time_s >= kNoiseUpdate_s) {
    s.noise_time_s = time_s;
    const Vec2 noise = p.noise_fraction * force.norm() * gaussian_pair(s.noise_rng);
    s.noise_n = Vec3(noise.x(), noise.y(), 0.0);
    // sin(w + phase) = sin w cos phase + cos w sin phase: one sine and cosine of w serve both axes.
    const double w = 2.0 * std::numbers::pi * p.tremor_frequency_hz * time_s;
    const Vec2 tremor = std::sin(w) * s.tremor_cos + std::cos(w) * s.tremor_sin;
    s.tremor_n = p.tremor_amplitude_n * Vec3(tremor.x(), tremor.y(), 0.0);
  }
  return force + s.noise_n + s.tremor_n;
}

}  // namespace calligraphy
