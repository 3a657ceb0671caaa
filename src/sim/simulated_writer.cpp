#include "calligraphy/sim/simulated_writer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// Minimum-jerk position profile on [0, 1] (Flash & Hogan 1985).
double minimum_jerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  return tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
}

constexpr double kDescendSeconds = 0.2;
constexpr double kTouchDownSeconds = 0.3;
constexpr double kHoverHeight = 0.002;
constexpr double kLiftSeconds = 0.2;
constexpr double kMinimumElementSeconds = 0.15;
constexpr double kNoiseUpdateSeconds = 1e-3;
constexpr int kSamplesPerElement = 48;

}  // namespace

WriterProfile WriterProfile::novice() {
  WriterProfile p;
  p.name = "novice";
  return p;
}

WriterProfile WriterProfile::skilled() {
  WriterProfile p;
  p.name = "skilled";
  p.hand_stiffness_n_per_m = 600.0;
  p.hand_damping_n_s_per_m = 8.0;
  p.writing_speed_m_s = 0.04;
  p.bias_offset_m = 0.0005;
  p.scale_error = 0.02;
  p.stroke_jitter_m = 0.0003;
  p.noise_fraction = 0.02;
  p.tremor_amplitude_n = 0.01;
  return p;
}

void WriterProfile::validate() const {
  const auto fail = [](const std::string& what) { throw InvalidArgument("WriterProfile: " + what); };
  if (!(hand_stiffness_n_per_m > 0.0) || !std::isfinite(hand_stiffness_n_per_m))
    fail("hand_stiffness_n_per_m must be > 0");
  if (!(hand_damping_n_s_per_m >= 0.0) || !std::isfinite(hand_damping_n_s_per_m))
    fail("hand_damping_n_s_per_m must be >= 0");
  if (!(writing_speed_m_s > 0.0) || !(travel_speed_m_s > 0.0)) fail("speeds must be > 0");
  if (!(press_depth_m >= 0.0) || !(lift_height_m > 0.0))
    fail("press_depth_m >= 0 and lift_height_m > 0 required");
  if (!(bias_offset_m >= 0.0) || !(stroke_jitter_m >= 0.0) || !(noise_fraction >= 0.0) ||
      !(tremor_amplitude_n >= 0.0) || !(overshoot_m >= 0.0)) {
    fail("bias, jitter, noise, tremor and overshoot must be >= 0");
  }
  if (!(scale_error > -0.5 && scale_error < 0.5)) fail("scale_error must be in (-0.5, 0.5)");
  if (!(correction_per_attempt >= 0.0 && correction_per_attempt <= 1.0))
    fail("correction_per_attempt must be in [0, 1]");
  if (max_attempts_per_stroke < 1) fail("max_attempts_per_stroke must be >= 1");
}

SimulatedWriter::SimulatedWriter(const Scene& scene, const WriterProfile& profile, std::uint64_t seed)
    : scene_(&scene), profile_(profile), rng_(seed), rest_(Vec3::Zero()) {
  profile_.validate();
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(rng_() >> 11) * 0x1p-53;
    character_offset_m_.push_back(profile_.bias_offset_m * Vec2(std::cos(angle), std::sin(angle)));
  }
  tremor_phase_x_ = 2.0 * std::numbers::pi * static_cast<double>(rng_() >> 11) * 0x1p-53;
  tremor_phase_y_ = 2.0 * std::numbers::pi * static_cast<double>(rng_() >> 11) * 0x1p-53;
}

double SimulatedWriter::gaussian() {
  // Box-Muller on our own uniform draws, so results do not depend on the standard library's distributions.
  const double u1 = (static_cast<double>(rng_() >> 11) + 0.5) * 0x1p-53;
  const double u2 = static_cast<double>(rng_() >> 11) * 0x1p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

Vec2 SimulatedWriter::copy_of(const Vec2& reference_m, std::size_t character) const {
  const Vec2 centre = scene_->characters[character].bounding_box.center();
  return centre + (1.0 + bias_scale_ * profile_.scale_error) * (reference_m - centre) +
         bias_scale_ * character_offset_m_[character];
}

void SimulatedWriter::add_motion(std::vector<Vec3> path, double speed_m_s, double minimum_s) {
  // Each motion starts where the previous one ended, so the hand's target never jumps.
  if (!motions_.empty()) path.insert(path.begin(), motions_.back().path.back());
  Motion m;
  m.arc.push_back(0.0);
  for (std::size_t i = 1; i < path.size(); ++i)
    m.arc.push_back(m.arc.back() + (path[i] - path[i - 1]).norm());
  m.path = std::move(path);
  m.t0 = plan_end_;
  m.duration = std::max(minimum_s, m.arc.back() / speed_m_s);
  plan_end_ = m.t0 + m.duration;
  motions_.push_back(std::move(m));
}

void SimulatedWriter::plan_stroke(std::size_t character, std::size_t stroke, double time_s,
                                  const Vec3& from) {
  motions_.clear();
  plan_end_ = time_s;
  const PlacedStroke& ref = scene_->characters[character].strokes[stroke];
  const double z0 = scene_->layout.paper_z_m;
  const double up = z0 + profile_.lift_height_m;
  const double down = z0 - profile_.press_depth_m;
  const Vec2 jitter = bias_scale_ * profile_.stroke_jitter_m * Vec2(gaussian(), gaussian());
  const auto on_paper = [&](const Vec2& p) {
    const Vec2 q = copy_of(p, character) + jitter;
    return Vec3(q.x(), q.y(), down);
  };
  const Vec3 start = on_paper(ref.start());
  // Travel above the paper to the start, then descend onto it.
  add_motion({from, Vec3(from.x(), from.y(), std::max(from.z(), up)), Vec3(start.x(), start.y(), up)},
             profile_.travel_speed_m_s, 0.3);
  // Descend quickly to just above the paper, then touch down gently, as writers do.
  const Vec3 hover(start.x(), start.y(), z0 + kHoverHeight);
  add_motion({Vec3(start.x(), start.y(), up), hover}, profile_.travel_speed_m_s, kDescendSeconds);
  add_motion({hover, start}, profile_.travel_speed_m_s, kTouchDownSeconds);
  // Write each element with its own minimum-jerk profile: writers pause at the feature points.
  for (std::size_t e = 0; e < ref.elements.size(); ++e) {
    const StrokeElement& element = ref.elements[e];
    std::vector<Vec3> path;
    for (int i = 0; i <= kSamplesPerElement; ++i)
      path.push_back(on_paper(element.point(static_cast<double>(i) / kSamplesPerElement)));
    if (profile_.overshoot_m > 0.0) {  // follow through past the feature point before turning
      const Vec2 tangent = element.unit_tangent(1.0);
      const Vec3 last = path.back();
      path.push_back(last + profile_.overshoot_m * Vec3(tangent.x(), tangent.y(), 0.0));
      if (e + 1 < ref.elements.size()) path.push_back(last);
    }
    add_motion(std::move(path), profile_.writing_speed_m_s, kMinimumElementSeconds);
  }
  const Vec3 end = motions_.back().path.back();
  add_motion({end, Vec3(end.x(), end.y(), up)}, profile_.travel_speed_m_s, kLiftSeconds);
}

void SimulatedWriter::observe(const RenderOutput& output, const DeviceState& pen) {
  const double time_s = pen.time_s;
  if (motions_.empty()) last_position_ = pen.position_m;
  if (done_ || time_s < plan_end_) return;
  if (output.finished) {
    done_ = true;
    return;
  }
  const bool same_stroke =
      !motions_.empty() && output.character == last_character_ && output.stroke == last_stroke_;
  if (same_stroke) {
    if (attempts_ >= profile_.max_attempts_per_stroke) {
      done_ = true;  // gives up on this stroke
      return;
    }
    ++attempts_;
    bias_scale_ *= 1.0 - profile_.correction_per_attempt;  // re-aim at the hint
  } else {
    attempts_ = 1;
    bias_scale_ = 1.0;
  }
  last_character_ = output.character;
  last_stroke_ = output.stroke;
  const Vec3 from = motions_.empty() ? last_position_ : motions_.back().path.back();
  plan_stroke(output.character, output.stroke, time_s, from);
}

Vec3 SimulatedWriter::target(double time_s) const {
  if (motions_.empty()) return last_position_;
  const auto it = std::find_if(motions_.begin(), motions_.end(),
                               [&](const Motion& m) { return time_s < m.t0 + m.duration; });
  const Motion& m = it == motions_.end() ? motions_.back() : *it;
  const double s = m.arc.back() * minimum_jerk((time_s - m.t0) / m.duration);
  const auto upper = std::upper_bound(m.arc.begin(), m.arc.end(), s);
  if (upper == m.arc.end()) return m.path.back();
  if (upper == m.arc.begin()) return m.path.front();
  const std::size_t i = static_cast<std::size_t>(upper - m.arc.begin());
  const double span = m.arc[i] - m.arc[i - 1];
  const double f = span > 0.0 ? (s - m.arc[i - 1]) / span : 0.0;
  return m.path[i - 1] + f * (m.path[i] - m.path[i - 1]);
}

Vec3 SimulatedWriter::hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) {
  if (motions_.empty()) last_position_ = position_m;  // before the first plan the hand holds still
  constexpr double h = 1e-4;
  const Vec3 x_d = target(time_s);
  const Vec3 v_d = (target(time_s + h) - target(time_s - h)) / (2.0 * h);
  const Vec3 force = profile_.hand_stiffness_n_per_m * (x_d - position_m) +
                     profile_.hand_damping_n_s_per_m * (v_d - velocity_m_s);
  if (time_s - noise_time_ >=
      kNoiseUpdateSeconds) {  // signal-dependent noise (Harris & Wolpert 1998), in plane
    noise_time_ = time_s;
    const double sigma = profile_.noise_fraction * force.norm();
    noise_ = Vec3(sigma * gaussian(), sigma * gaussian(), 0.0);
  }
  const double w = 2.0 * std::numbers::pi * profile_.tremor_frequency_hz * time_s;
  const Vec3 tremor =
      profile_.tremor_amplitude_n * Vec3(std::sin(w + tremor_phase_x_), std::sin(w + tremor_phase_y_), 0.0);
  return force + noise_ + tremor;
}

}  // namespace calligraphy
