#pragma once
// How the simulated writer's hand moves the pen along a plan (private to the sim module): the program's
// minimum-jerk segments run by a phase whose rate follows the writer's pace (the steering law), the visual
// correction of the target, the motor command held between observations, and the hand's impedance with
// signal-dependent noise and tremor on the stylus; and what the hand feels of a resistance against its
// motion.
#include <cstdint>
#include <random>
#include <vector>

#include "calligraphy/trial/writer_profile.hpp"
#include "sim/writer_program.hpp"

namespace calligraphy::writer_detail {

/// What became of the program over one `advance_to`.
struct MotorStep {
  double dt_s = 0.0;           // time since the last observation [s]
  bool touched_down = false;   // a write segment began (the pen on the paper to write) ...
  double touch_down_s = 0.0;   // ... at this time [s], the first such in the step
  bool mid_lift = false;       // a segment of a lift in the middle of a stroke began
  bool program_ended = false;  // the last segment ended: the program ran out
};

/// The error the writer sees, and what the hand is doing meanwhile.
struct SeenError {
  Vec2 error_m = Vec2::Zero();  // from the seen pen to where it should be [m]
  bool travelling = true;       // pen-up between strokes (or no attempt under way)
  bool writing = false;         // along a stroke: the error across it sets the pace
};

class WriterMotorModel {
 public:
  /// Draws the tremor's phases from a stream seeded with `noise_seed`, which then draws the hand's noise.
  /// `profile` must outlive the model.
  WriterMotorModel(const WriterProfile& profile, std::uint64_t noise_seed);

  /// True once the first observation has started the hand.
  [[nodiscard]] bool started() const noexcept { return started_; }
  /// The first observation, at `time_s` [s] with the pen at `position_m` [m]: the hand holds it there.
  void start(double time_s, const Vec3& position_m);
  /// Runs the program on to `time_s` [s] (not before the last observation) and moves the visual
  /// correction on at its rate.
  MotorStep advance_to(double time_s);
  /// Makes `program` the hand's program, from its start.
  void follow(std::vector<Segment> program);
  /// The program has run out: the hand holds still at `hold_m()`.
  [[nodiscard]] bool idle() const noexcept { return program_.empty(); }
  /// The segment running, or nullptr when idle.
  [[nodiscard]] const Segment* segment() const noexcept;
  /// Where the last segment ended (or the pen was at the start) [m].
  [[nodiscard]] const Vec3& hold_m() const noexcept { return hold_; }
  /// Where the program puts the hand now, without the correction [m].
  [[nodiscard]] Vec3 planned_now() const;

  /// Touch: whether `force_n` [N] on the stylus has resisted the intended motion along a write segment,
  /// beyond the paper's usual drag, for the reaction time (over steps of `dt_s` [s]). `may_be_refused`:
  /// the stroke is one the display can still refuse; otherwise, and off a write segment or in its
  /// follow-through, nothing counts.
  [[nodiscard]] bool resisted(const Vec3& force_n, double dt_s, bool may_be_refused);
  /// Vision, every vision period: corrects the target by the seen error beyond the tolerance (or lets the
  /// correction fade while travelling), and while writing filters the seen error that sets the pace.
  void see_error(const SeenError& seen);
  /// Steering law: moves the speed factor towards the pace the seen error allows, over `dt_s` [s].
  void pace(double dt_s);
  /// Sets the phase's rate from the running segment's duration and, if steered, the speed factor.
  void update_rate();
  /// The motor command at `time_s` [s]: the plan's point and velocity then, held until the next.
  void issue_command(double time_s);
  /// The hand's target x_d at `time_s` [m]: the last command held to first order (or the held point).
  [[nodiscard]] Vec3 target(double time_s) const;
  /// The hand's force on the stylus [N] at `time_s` [s] with the stylus at `position_m` [m] moving at
  /// `velocity_m_s` [m/s]: the impedance towards the command, with noise and tremor.
  Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s);

 private:
  [[nodiscard]] Motion desired(double time_s) const;

  const WriterProfile* profile_;

  // The program and its phase.
  std::vector<Segment> program_;
  std::size_t current_ = 0;
  double phase_ = 0.0;
  double rate_per_s_ = 0.0;
  Vec3 hold_ = Vec3::Zero();
  bool started_ = false;
  double observed_s_ = 0.0;

  // Closed loop: visual correction of x_d, pace and the resistance felt.
  Vec2 correction_m_ = Vec2::Zero();
  Vec2 correction_rate_m_s_ = Vec2::Zero();
  double seen_error_m_ = 0.0;
  double speed_factor_ = 1.0;
  double resisted_s_ = 0.0;

  // The motor command issued at the last observation: where the plan puts the hand and how fast it moves
  // there; the hand follows its first-order hold until the next observation.
  Motion command_;
  double command_s_ = 0.0;

  // The hand's noise and tremor, held for kNoiseUpdate_s.
  std::mt19937_64 noise_rng_;
  Vec3 noise_n_ = Vec3::Zero();
  double noise_time_s_ = -1.0;
  Vec2 tremor_cos_ = Vec2::Ones();  // the cosines and sines of the tremor's phases on x and y
  Vec2 tremor_sin_ = Vec2::Zero();
  Vec3 tremor_n_ = Vec3::Zero();
};

}  // namespace calligraphy::writer_detail
