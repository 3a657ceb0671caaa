#include "sim/writer_motor_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "sim/writer_random.hpp"

namespace calligraphy::writer_detail {

namespace {

constexpr double kNoiseUpdate_s = 1e-3;     // the hand's noise is redrawn every millisecond
constexpr double kCorrectionDecay_s = 0.3;  // the visual correction fades while travelling pen-up

// The error vector shortened by the tolerance: no correction within it, continuous at its edge.
Vec2 beyond_tolerance(const Vec2& error, double tolerance) {
  const double n = error.norm();
  return n > tolerance ? Vec2(error * (1.0 - tolerance / n)) : Vec2(Vec2::Zero());
}

}  // namespace

WriterMotorModel::WriterMotorModel(const WriterProfile& profile, std::uint64_t noise_seed)
    : profile_(&profile), noise_rng_(noise_seed) {
  const double tremor_phase_x = 2.0 * std::numbers::pi * uniform(noise_rng_);
  const double tremor_phase_y = 2.0 * std::numbers::pi * uniform(noise_rng_);
  tremor_cos_ = Vec2(std::cos(tremor_phase_x), std::cos(tremor_phase_y));
  tremor_sin_ = Vec2(std::sin(tremor_phase_x), std::sin(tremor_phase_y));
}

void WriterMotorModel::start(double time_s, const Vec3& position_m) {
  started_ = true;
  observed_s_ = time_s;
  hold_ = position_m;
}

const Segment* WriterMotorModel::segment() const noexcept {
  return current_ < program_.size() ? &program_[current_] : nullptr;
}

Vec3 WriterMotorModel::planned_now() const {
  return current_ < program_.size() ? program_[current_].at_phase(phase_) : hold_;
}

// The hand's target: the program's point now, moved by the correction, and its exact time derivative (the
// hand's damping acts on the error in velocity, Flash & Hogan's minimum-jerk speed profile included).
Motion WriterMotorModel::desired(double time_s) const {
  const double ahead = time_s - observed_s_;
  Motion motion{hold_, Vec3::Zero()};
  if (current_ < program_.size()) {
    const double unclamped = phase_ + rate_per_s_ * ahead;
    motion = program_[current_].motion_at_phase(std::clamp(unclamped, 0.0, 1.0), rate_per_s_);
  }
  const Vec2 c = correction_m_ + correction_rate_m_s_ * ahead;
  motion.position_m += Vec3(c.x(), c.y(), 0.0);
  motion.velocity_m_s += Vec3(correction_rate_m_s_.x(), correction_rate_m_s_.y(), 0.0);
  return motion;
}

void WriterMotorModel::update_rate() {
  if (current_ >= program_.size()) {
    rate_per_s_ = 0.0;
    return;
  }
  const Segment& s = program_[current_];
  rate_per_s_ = (s.steered ? speed_factor_ : 1.0) / s.duration_s;
}

void WriterMotorModel::follow(std::vector<Segment> program) {
  program_ = std::move(program);
  current_ = 0;
  phase_ = 0.0;
  resisted_s_ = 0.0;
  update_rate();
}

MotorStep WriterMotorModel::advance_to(double time_s) {
  MotorStep step;
  step.dt_s = std::max(0.0, time_s - observed_s_);
  correction_m_ += correction_rate_m_s_ * step.dt_s;
  observed_s_ = time_s;
  if (program_.empty()) return step;
  phase_ += rate_per_s_ * step.dt_s;
  while (current_ < program_.size() && phase_ >= 1.0) {
    // The next segment starts when this one ended, between the observations.
    const double beyond_s = rate_per_s_ > 0.0 ? (phase_ - 1.0) / rate_per_s_ : 0.0;
    hold_ = program_[current_].path.back();
    ++current_;
    phase_ = 0.0;
    resisted_s_ = 0.0;
    if (current_ >= program_.size()) break;
    const Segment& s = program_[current_];
    if (s.kind == SegmentKind::write && !step.touched_down) {
      step.touched_down = true;
      step.touch_down_s = time_s - beyond_s;
    }
    if (s.mid_stroke) step.mid_lift = true;
    update_rate();
    phase_ = rate_per_s_ * beyond_s;
  }
  if (current_ >= program_.size()) {
    program_.clear();
    current_ = 0;
    phase_ = 0.0;
    step.program_ended = true;
  }
  return step;
}

// A force against the intended motion, beyond the paper's usual drag, for the reaction time means the
// display refuses the stroke (the resistance of Fig. 4, the off-stroke resistance).
bool WriterMotorModel::resisted(const Vec3& force_n, double dt_s, bool may_be_refused) {
  if (!may_be_refused || current_ >= program_.size()) {
    resisted_s_ = 0.0;
    return false;
  }
  const Segment& s = program_[current_];
  const double along = s.length_m() * Segment::minimum_jerk(phase_);
  if (s.kind != SegmentKind::write || along >= s.follow_from_m) {
    resisted_s_ = 0.0;
    return false;
  }
  const Vec2 intended = s.direction_at_arc(along);
  const double against =
      -force_n.head<2>().dot(intended) - profile_->expected_drag_ratio * std::max(force_n.z(), 0.0);
  resisted_s_ = (!intended.isZero() && against > profile_->resistance_threshold_n) ? resisted_s_ + dt_s : 0.0;
  return resisted_s_ >= profile_->reaction_time_s;
}

void WriterMotorModel::see_error(const SeenError& seen) {
  const WriterProfile& p = *profile_;
  if (seen.travelling) {
    correction_rate_m_s_ = -correction_m_ / kCorrectionDecay_s;
  } else {
    correction_rate_m_s_ = p.correction_rate_per_s * beyond_tolerance(seen.error_m, p.error_tolerance_m);
  }
  if (seen.writing) {
    const double blend = 1.0 - std::exp(-p.vision_period_s / p.error_filter_s);
    seen_error_m_ += blend * (seen.error_m.norm() - seen_error_m_);
  }
}

// Steering law, local form v = W_free / tau with W_free = W - 2 |e| (Accot & Zhai 1997), tau = W / v0.
void WriterMotorModel::pace(double dt_s) {
  const WriterProfile& p = *profile_;
  const double target = std::clamp(1.0 - 2.0 * seen_error_m_ / p.steering_width_m, p.min_speed_fraction, 1.0);
  speed_factor_ += (1.0 - std::exp(-dt_s / p.speed_time_constant_s)) * (target - speed_factor_);
}

void WriterMotorModel::issue_command(double time_s) {
  command_ = desired(time_s);
  command_s_ = time_s;
}

Vec3 WriterMotorModel::target(double time_s) const {
  return started_ ? Vec3(command_.position_m + (time_s - command_s_) * command_.velocity_m_s) : hold_;
}

Vec3 WriterMotorModel::hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) {
  const WriterProfile& p = *profile_;
  if (!started_) hold_ = position_m;  // before the first observation the hand holds still
  const Vec3 x_d = target(time_s);
  const Vec3 v_d = started_ ? command_.velocity_m_s : Vec3(Vec3::Zero());
  const Vec3 force =
      p.hand_stiffness_n_per_m * (x_d - position_m) + p.hand_damping_n_s_per_m * (v_d - velocity_m_s);
  // Signal-dependent noise (Harris & Wolpert 1998) and the physiological tremor, in plane, both held for
  // kNoiseUpdate_s: the 8-12 Hz tremor is smooth on that scale, and a sine per physics substep cost a
  // tenth of a simulated trial.
  if (time_s - noise_time_s_ >= kNoiseUpdate_s) {
    noise_time_s_ = time_s;
    const Vec2 noise = p.noise_fraction * force.norm() * gaussian_pair(noise_rng_);
    noise_n_ = Vec3(noise.x(), noise.y(), 0.0);
    // sin(w + phase) = sin w cos phase + cos w sin phase: one sine and cosine of w serve both axes.
    const double w = 2.0 * std::numbers::pi * p.tremor_frequency_hz * time_s;
    const Vec2 tremor = std::sin(w) * tremor_cos_ + std::cos(w) * tremor_sin_;
    tremor_n_ = p.tremor_amplitude_n * Vec3(tremor.x(), tremor.y(), 0.0);
  }
  return force + noise_n_ + tremor_n_;
}

}  // namespace calligraphy::writer_detail
