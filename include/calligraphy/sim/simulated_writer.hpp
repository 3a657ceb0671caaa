#pragma once
/// \file simulated_writer.hpp
/// A simulated writer for tests and experiments. It holds the stylus through a hand impedance
/// F = k (x_d - x) + b (x_d' - x') + noise + tremor (the noise grows with the force, after Harris &
/// Wolpert 1998) and moves x_d along its own copy of the reference strokes: minimum-jerk motion
/// (Flash & Hogan 1985) per stroke element, pen lifts between strokes, pressing into the paper while
/// writing. Its copy carries a systematic bias (an offset and a mis-scale of the character) so that
/// guidance has work to do. It follows the display: it writes the stroke whose start is hinted (the
/// active stroke), and when a stroke was not accepted it re-aims at the hint with less bias, up to a
/// number of attempts. All randomness is seeded.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/simulated_device.hpp"

namespace calligraphy {

/// How a simulated writer writes. Units as named.
struct WriterProfile {
  std::string name;
  double hand_stiffness_n_per_m = 150.0;  ///< k of the hand impedance [N/m]
  double hand_damping_n_s_per_m = 3.0;    ///< b of the hand impedance [N s/m]
  double writing_speed_m_s = 0.025;       ///< mean speed along an element while writing [m/s]
  double travel_speed_m_s = 0.08;         ///< mean speed of pen-up moves [m/s]
  double press_depth_m = 0.005;           ///< how far below the paper the hand aims while writing [m]
  double lift_height_m = 0.01;            ///< pen-up height above the paper [m]
  double bias_offset_m = 0.002;           ///< systematic offset of the whole character copy [m]
  double scale_error = 0.06;              ///< relative mis-scale of the copy about the character centre
  double stroke_jitter_m = 0.001;         ///< standard deviation of a per-stroke random offset [m]
  double noise_fraction = 0.05;           ///< signal-dependent force noise, std dev / |F_hand|
  double tremor_amplitude_n = 0.05;       ///< in-plane tremor force amplitude [N]
  double tremor_frequency_hz = 9.0;       ///< tremor frequency [Hz] (8-12 Hz physiological)
  double overshoot_m = 0.003;             ///< follow-through past each feature point (turns, the end) [m]
  double correction_per_attempt = 0.5;    ///< share of the bias removed on each re-aim after a miss
  int max_attempts_per_stroke = 3;

  /// A relaxed learner with a visible bias (150 N/m, 3 N s/m: assumed grip figures, not measured).
  static WriterProfile novice();
  /// A stiffer, faster, nearly unbiased writer (600 N/m, 8 N s/m).
  static WriterProfile skilled();
  /// Throws InvalidArgument naming the field when a value is out of range.
  void validate() const;
};

class SimulatedWriter final : public HandModel {
 public:
  /// `scene` must outlive the writer. Throws InvalidArgument for a bad profile.
  SimulatedWriter(const Scene& scene, const WriterProfile& profile, std::uint64_t seed);

  Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) override;
  /// Feedback after each servo tick: what the display shows (active stroke, state) and where the
  /// writer sees its own pen (the device state).
  void observe(const RenderOutput& output, const DeviceState& pen);
  /// True when the writer has finished or given up.
  [[nodiscard]] bool done() const noexcept { return done_; }
  /// The hand's target at time t [m] (for tests).
  [[nodiscard]] Vec3 target(double time_s) const;

 private:
  struct Motion {  // x_d moves along `path` with minimum-jerk timing over [t0, t0 + duration]
    std::vector<Vec3> path;
    std::vector<double> arc;  // cumulative length along path
    double t0 = 0.0;
    double duration = 0.0;
  };
  void plan_stroke(std::size_t character, std::size_t stroke, double time_s, const Vec3& from);
  void add_motion(std::vector<Vec3> path, double speed_m_s, double minimum_s);
  Vec2 copy_of(const Vec2& reference_m, std::size_t character) const;
  double gaussian();

  const Scene* scene_;
  WriterProfile profile_;
  std::mt19937_64 rng_;
  std::vector<Vec2> character_offset_m_;
  std::vector<Motion> motions_;
  double plan_end_ = 0.0;
  Vec3 rest_;
  bool done_ = false;
  bool finished_seen_ = false;
  std::size_t last_character_ = 0;
  std::size_t last_stroke_ = 0;
  int attempts_ = 0;
  double bias_scale_ = 1.0;
  Vec3 noise_ = Vec3::Zero();
  double noise_time_ = -1.0;
  double tremor_phase_x_ = 0.0;
  double tremor_phase_y_ = 0.0;
  Vec3 last_position_ = Vec3::Zero();
};

}  // namespace calligraphy
