#include "calligraphy/sim/simulated_writer.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "sim/writer_error_injector.hpp"
#include "sim/writer_motor_model.hpp"
#include "sim/writer_planner.hpp"
#include "sim/writer_program.hpp"
#include "sim/writer_random.hpp"
#include "sim/writer_vision.hpp"

namespace calligraphy {

using writer_detail::make_segment;
using writer_detail::NextStroke;
using writer_detail::Segment;
using writer_detail::SegmentKind;

namespace {

WriterProfile validated(const WriterProfile& profile) {
  profile.validate();
  return profile;
}

// The seeds of the plan's stream and of the hand's noise, in this order, from the writer's seed.
struct WriterSeeds {
  std::uint64_t plan = 0;
  std::uint64_t noise = 0;
};

WriterSeeds split_seeds(std::uint64_t seed) {
  WriterSeeds seeds;
  seeds.plan = writer_detail::split_seed(seed);
  seeds.noise = writer_detail::split_seed(seed);
  return seeds;
}

}  // namespace

// The writer: its planner says what to write, the error injector spoils it as the profile says, the motor
// model moves the hand along it, and vision and touch close the loop.
struct SimulatedWriter::State {
  WriterProfile profile;
  const Scene* scene;
  writer_detail::WriterErrorInjector errors;
  writer_detail::WriterPlanner planner;
  writer_detail::WriterMotorModel motor;
  writer_detail::WriterVision vision;
  double next_vision_s = 0.0;

  State(const Scene& s, const WriterProfile& p, std::uint64_t seed) : State(s, p, split_seeds(seed)) {}
  State(const Scene& s, const WriterProfile& p, const WriterSeeds& seeds)
      : profile(validated(p)),
        scene(&s),
        errors(profile),
        planner(s, profile, errors, seeds.plan),
        motor(profile, seeds.noise),
        vision(profile.visual_delay_s) {}

  void observe(const RenderOutput& output, const DeviceState& pen);
  void record(const writer_detail::MotorStep& step, double time_s);
  void feel(const RenderOutput& output, double dt_s, double time_s);
  void look(double time_s);
  [[nodiscard]] writer_detail::SeenError seen_error(const Vec2& seen_pen) const;
  void break_off(double time_s, AttemptEnd why, NextStroke then);
};

void SimulatedWriter::State::observe(const RenderOutput& output, const DeviceState& pen) {
  const double time_s = pen.time_s;
  if (!motor.started()) {
    motor.start(time_s, pen.position_m);
    next_vision_s = time_s;
  }
  const writer_detail::MotorStep step = motor.advance_to(time_s);
  record(step, time_s);
  vision.store(output, pen);
  if (planner.done()) {
    motor.issue_command(time_s);
    return;
  }
  feel(output, step.dt_s, time_s);
  while (time_s >= next_vision_s) {
    look(time_s);
    next_vision_s += profile.vision_period_s;
  }
  motor.pace(step.dt_s);
  if (motor.idle()) motor.follow(planner.next_program(time_s, motor.hold_m()));
  motor.update_rate();
  motor.issue_command(time_s);
}

// What the hand did to the attempt under way: touched down to write, lifted in the middle, wrote it all.
void SimulatedWriter::State::record(const writer_detail::MotorStep& step, double time_s) {
  if (step.touched_down) planner.touched_down(step.touch_down_s);
  if (step.mid_lift) planner.reached_mid_lift();
  if (step.program_ended) planner.complete_attempt(time_s);
}

// Touch: a resistance against the intended motion for the reaction time is the display refusing the
// stroke; the writer breaks off and writes the stroke the display hints.
void SimulatedWriter::State::feel(const RenderOutput& output, double dt_s, double time_s) {
  const writer_detail::OpenAttempt& attempt = planner.attempt();
  const bool may_be_refused = !attempt.ended && !attempt.accepted;
  if (motor.resisted(output.force_n, dt_s, may_be_refused) && !planner.moved_on()) {
    planner.count_refusal();
    break_off(time_s, AttemptEnd::refused, NextStroke::hint);
  }
}

// Vision, every vision_period_s: the pen and the display as they were visual_delay_s ago.
void SimulatedWriter::State::look(double time_s) {
  const writer_detail::VisionSample* seen = vision.seen_at(time_s - profile.visual_delay_s);
  if (seen == nullptr) return;
  // A stroke cleared after a lift in the middle of it: write it again.
  const bool cleared = vision.take_in(*seen);
  if (cleared && !planner.attempt().ended && planner.attempt().mid_lift_reached) {
    break_off(time_s, AttemptEnd::interrupted, NextStroke::redo);
  }
  planner.see_display(seen->character, seen->stroke, seen->finished);
  motor.see_error(seen_error(seen->pen));
}

// The error the writer sees with its pen at `seen_pen` [m]: towards the stroke's start while aiming at it,
// across the stroke while writing it (along it the writer is where its pace puts it), none otherwise.
writer_detail::SeenError SimulatedWriter::State::seen_error(const Vec2& seen_pen) const {
  writer_detail::SeenError seen;
  const Segment* s = motor.segment();
  const writer_detail::OpenAttempt& attempt = planner.attempt();
  if (s == nullptr || attempt.ended) return seen;
  seen.travelling = s->kind == SegmentKind::travel;
  if (s->aim_at_start) {
    seen.error_m = attempt.start_m - seen_pen;
  } else if (s->kind == SegmentKind::write) {
    const writer_detail::PolylineFoot foot = writer_detail::nearest_on_polyline(attempt.reference, seen_pen);
    const Vec2 e = foot.foot - seen_pen;
    seen.error_m = e - e.dot(foot.direction) * foot.direction;
    seen.writing = true;
  }
  return seen;
}

// Ends the attempt and lifts the pen from where the plan has it now; then the writer writes `then`.
void SimulatedWriter::State::break_off(double time_s, AttemptEnd why, NextStroke then) {
  if (!planner.break_off(time_s, why, then)) return;
  const Vec3 here = motor.planned_now();
  const double up = scene->layout.paper_z_m + profile.lift_height_m;
  std::vector<Segment> lift;
  lift.push_back(make_segment(SegmentKind::lift, {here, Vec3(here.x(), here.y(), std::max(here.z(), up))},
                              profile.travel_speed_m_s, writer_detail::kLift_s));
  motor.follow(std::move(lift));
}

SimulatedWriter::SimulatedWriter(const Scene& scene, const WriterProfile& profile, std::uint64_t seed)
    : state_(std::make_unique<State>(scene, profile, seed)) {}
SimulatedWriter::~SimulatedWriter() = default;
SimulatedWriter::SimulatedWriter(SimulatedWriter&&) noexcept = default;
SimulatedWriter& SimulatedWriter::operator=(SimulatedWriter&&) noexcept = default;

bool SimulatedWriter::done() const noexcept { return state_->planner.done(); }
const WriterLog& SimulatedWriter::log() const noexcept { return state_->planner.log(); }
const std::vector<PlannedStroke>& SimulatedWriter::plan() const noexcept { return state_->planner.plan(); }
const WriterProfile& SimulatedWriter::profile() const noexcept { return state_->profile; }

Vec3 SimulatedWriter::target(double time_s) const { return state_->motor.target(time_s); }

void SimulatedWriter::observe(const RenderOutput& output, const DeviceState& pen) {
  state_->observe(output, pen);
}

Vec3 SimulatedWriter::hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) {
  return state_->motor.hand_force(time_s, position_m, velocity_m_s);
}

}  // namespace calligraphy
