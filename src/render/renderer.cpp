#include "calligraphy/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "calligraphy/collision/constraint_space.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "core/library_log.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {
namespace {

double smoothstep(double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

// Rounding a corner: near the end of an element that another follows, a hand turns where the median it
// follows turns, inside the fitted corner point (by up to a few millimetres: the fitted corner is where the
// two elements' lines meet), so that the active element's line, its backward resistance and the off-stroke
// damper all lie across its way. There the fixture goes slack: weight 1 within R_res / 2 of the corner
// point, 0 beyond R_res, a smoothstep between, so the force stays continuous; past the corner the next
// element guides again. Returns that weight: the in-plane guidance is scaled by 1 - weight.
double corner_slack(const ActiveStroke& active, const Vec2& tip, double radius_m) noexcept {
  const PlacedStroke* stroke = active.stroke();
  const std::size_t e = active.element_index();
  if (stroke == nullptr || e + 1 >= stroke->elements.size() || !(radius_m > 0.0)) return 0.0;
  const double d = (tip - stroke->elements[e].end()).norm();
  return smoothstep((radius_m - d) / (0.5 * radius_m));
}

// The safety chain's parameters with the device's peak and continuous force filled in, and a peak or
// continuous force given above the device's taken as the device's: the chain never commands (and the trace
// never records) a force the device cannot give, which its driver would clamp unseen.
SafetyChainParameters chain_parameters(const RendererOptions& options, const DeviceInfo& device) {
  SafetyChainParameters p = options.safety;
  p.max_force_n = p.max_force_n == 0.0 ? device.max_force_n : std::min(p.max_force_n, device.max_force_n);
  double continuous = p.max_continuous_force_n;
  if (continuous == 0.0) {
    continuous = device.max_continuous_force_n;  // the device's (0, unknown: the stage is off)
  } else if (device.max_continuous_force_n > 0.0) {
    continuous = std::min(continuous, device.max_continuous_force_n);
  }
  p.max_continuous_force_n = std::min(continuous, p.max_force_n);
  return p;
}

const DeviceInfo& checked(const DeviceInfo& device) {
  if (!(device.max_force_n > 0.0) || !std::isfinite(device.max_force_n)) {
    throw InvalidArgument("Renderer: device '" + device.model + "' max_force_n = " +
                          shortest_decimal(device.max_force_n) + " must be finite and > 0");
  }
  return device;
}

}  // namespace

void RendererOptions::validate() const {
  if (!servo_rate_allowed(rate_hz, false)) {
    throw InvalidArgument("RendererOptions.rate_hz = " + detail::rate_text(rate_hz) + " must be in " +
                          servo_rate_range_text(false));
  }
  check_low_pass_cutoff(safety.low_pass_cutoff_hz, rate_hz);
  passivity.validate();
}

Renderer::Renderer(const Scene& scene, const ForceLawParameters& parameters, const DeviceInfo& device,
                   const RendererOptions& options)
    : Renderer(scene, Checked<ForceLawParameters>::check(parameters), device,
               Checked<RendererOptions>::check(options)) {}

Renderer::Renderer(const Scene& scene, const Checked<ForceLawParameters>& parameters,
                   const DeviceInfo& device, const Checked<RendererOptions>& options)
    : scene_(&scene),
      parameters_(*parameters),
      options_(*options),
      period_s_(1.0 / options->rate_hz),
      active_(scene, parameters->acceptance),
      chain_(chain_parameters(*options, checked(device)), options->rate_hz),
      passivity_(options->passivity, options->rate_hz) {
  const GuidanceLaw& law = parameters_.guidance_law;
  mode_ = mode_of(law);
  guidance_reach_m_ = parameters_.constraint_radius_m;
  if (const auto* fading = std::get_if<FadingGuidance>(&law)) guidance_gain_ = fading->gain;
  if (const auto* replay = std::get_if<ReplayGuidance>(&law)) {
    replay_ = TeacherReplay(scene, replay->teacher_trajectory, parameters_);
    guidance_reach_m_ = replay->max_lead_m;
  }
  if (const auto* assist = std::get_if<AssistAsNeededGuidance>(&law)) assist_band_m_ = assist->band_m;
  if (const auto* amplification = std::get_if<ErrorAmplificationGuidance>(&law)) {
    guidance_gain_ = amplification->gain;
    guidance_max_force_n_ = amplification->max_force_n;
  }
  if (const auto* timing = std::get_if<TimingGuidance>(&law)) {
    timing_ = TimingTarget(scene, timing->speed_m_s);
    guidance_reach_m_ = timing->max_lead_m;
  }
  off_stroke_alpha_ =
      1.0 - std::exp(-2.0 * std::numbers::pi * parameters_.off_stroke_velocity_cutoff_hz * period_s_);
  const double k_paper = parameters_.paper_stiffness_n_per_m;
  const double k_guidance = parameters_.guidance_stiffness_n_per_m;
  const double k_max = device.max_stiffness_n_per_m;
  if (k_max > 0.0 && (k_paper > k_max || k_guidance > k_max)) {
    calligraphy::detail::library_log().warn(
        "stiffness above the device's stable maximum of {} N/m ({}): paper {} N/m, guidance {} N/m", k_max,
        device.model, k_paper, k_guidance);
  }
  const double b_device = device.intrinsic_damping_n_s_per_m;
  if (!std::isfinite(b_device) || b_device < 0.0) {
    throw InvalidArgument("DeviceInfo.intrinsic_damping_n_s_per_m = " + shortest_decimal(b_device) +
                          " must be finite and >= 0");
  }
  if (b_device > 0.0) {
    // Colgate & Schenkel 1997: K < 2 (b - B) / T. The paper has the virtual damper B; the guidance
    // stiffness is scaled by the attraction factor (eq. 8) on top.
    const double paper_bound =
        colgate_stiffness_bound(b_device, options_.rate_hz, parameters_.paper_damping_n_s_per_m);
    const double guidance_bound = colgate_stiffness_bound(b_device, options_.rate_hz);
    if (k_paper > paper_bound) {
      calligraphy::detail::library_log().warn(
          "paper stiffness {} N/m above the passivity bound 2 (b - B) / T = {} N/m (b = {} N s/m, B = {} "
          "N s/m, {} Hz): the contact may be unstable without a hand or the passivity controller",
          k_paper, paper_bound, b_device, parameters_.paper_damping_n_s_per_m, options_.rate_hz);
    }
    if (parameters_.guidance && k_guidance > guidance_bound) {
      calligraphy::detail::library_log().warn(
          "guidance stiffness {} N/m above the passivity bound 2 b / T = {} N/m (b = {} N s/m, {} Hz)",
          k_guidance, guidance_bound, b_device, options_.rate_hz);
    }
  }
}

void Renderer::reset() noexcept {
  active_.reset();
  state_ = InteractionState::separation;
  chain_.reset();
  passivity_.reset();
  tracker_.reset();
  foot_valid_ = false;
  paper_weight_ = 0.0;
  guidance_ = fade_from_ = Vec2::Zero();
  fade_elapsed_s_ = 0.0;
  was_inside_ = false;
  writing_since_s_ = 0.0;
  off_stroke_velocity_ = Vec2::Zero();
  anchor_valid_ = false;
  contact_ = RefusedPenDown{};
  contact_tip_m_ = Vec2::Zero();
}

// F_et (eq. 8) with the taper at R_res and a rate-limited foot point, plus the resistance force, for
// the active element; zero outside the constraint space. Fills the contact fields of `out`.
Vec2 Renderer::guidance_force(const DeviceState& device, RenderOutput& out, bool element_changed,
                              double slack) noexcept {
  const StrokeElement& element = *active_.element();
  const Vec2 tip = device.position_m.head<2>();
  if (element_changed) tracker_.reset();
  // An LSE's foot point is exact and cheap; a CSE's is tracked from tick to tick (nearest_point_tracker.hpp).
  const NearestPoint nearest = element.degree == 1
                                   ? nearest_point_on_segment(element.start(), element.end(), tip)
                                   : tracker_.update(element, tip);
  ElementContact contact = element_contact_at(element, tip, nearest, parameters_.constraint_radius_m);
  // Past the end of a written stroke there is nothing to pull the pen back to (it completes at the lift).
  if (active_.attempt().passed_end()) contact.inside = false;
  out.in_constraint_space = contact.inside;
  out.foot_m = nearest.foot;
  // Foot-point jumps (a new element, a jump of the tracker to another minimum) move the attraction
  // target at a bounded speed instead of stepping the force.
  // In the replay mode the attraction point is where the teacher was, as many seconds into the stroke as
  // the pen has been writing it, kept on the active element, with the same bounded speed; in the timing
  // mode it is the minimum-jerk target that many seconds into the stroke.
  const GuidanceMode mode = mode_;
  const double elapsed_s = device.time_s - writing_since_s_;
  const Vec2 attraction_point =
      mode == GuidanceMode::replay
          ? replay_.attraction_point(active_.strokes_written(), elapsed_s, active_.element_index(), element)
      : mode == GuidanceMode::timing
          ? timing_.attraction_point(active_.strokes_written(), elapsed_s, active_.element_index(), element)
          : nearest.foot;
  const double max_move = parameters_.max_foot_speed_m_s * period_s_;
  const Vec2 move = attraction_point - rendered_foot_;
  if (!foot_valid_ || element_changed) {
    rendered_foot_ = attraction_point;
  } else if (move.norm() > max_move) {
    rendered_foot_ += move * (max_move / move.norm());
  } else {
    rendered_foot_ = attraction_point;
  }
  foot_valid_ = true;
  if (!parameters_.guidance || !contact.inside) return Vec2::Zero();
  const double taper =
      constraint_taper(nearest.distance, parameters_.constraint_radius_m, parameters_.constraint_taper_m);
  const Vec2 tangent = element.unit_tangent(nearest.t);
  const double factor = guidance_gain_ * active_.attraction(nearest.t);
  const double stiffness = parameters_.guidance_stiffness_n_per_m;
  Vec2 attraction = attraction_force(tip, rendered_foot_, stiffness, factor);
  // Assist-as-needed: the spring acts on the deviation beyond the band only, K a (d - b)+, continuous at b.
  if (mode == GuidanceMode::assist_as_needed) {
    const double d = (rendered_foot_ - tip).norm();
    attraction *= d > assist_band_m_ ? (d - assist_band_m_) / d : 0.0;
  }
  // Error amplification: the same field turned round, pushing the pen off the element.
  if (mode == GuidanceMode::error_amplification) attraction = -attraction;
  // A pen past the element's end (its foot clamped there) is pulled onto the line, never back along the
  // stroke to an end or corner it has passed; on the end plane the along-stroke part is zero, so this is
  // continuous. Timing guidance is the opposite: along the stroke only, never across it.
  if (mode == GuidanceMode::timing) {
    attraction = attraction.dot(tangent) * tangent;
  } else if (nearest.t >= 1.0) {
    attraction -= attraction.dot(tangent) * tangent;
  }
  attraction *= 1.0 - slack;
  // The replay and timing points may lead or trail the pen along the stroke by more than R_res: the spring
  // is saturated at its force at their max_lead_m, so the force stays bounded and continuous. (The foot
  // point of the other modes is never further than R_res.) The repulsive field has its own bound.
  const double limit = std::min(stiffness * factor * guidance_reach_m_, guidance_max_force_n_);
  const double magnitude = attraction.norm();
  if (magnitude > limit) attraction *= limit / magnitude;
  // Timing guidance leaves the direction to the writer too: no resistance to moving backwards.
  const double resistance = mode == GuidanceMode::timing ? 0.0 : parameters_.resistance_damping_n_s_per_m;
  return taper * attraction +
         (1.0 - slack) * resistance_force(device.velocity_m_s.head<2>(), tangent, resistance);
}

RenderOutput Renderer::tick(const DeviceState& device) noexcept {
  RenderOutput out;
  // `!(|x| <= limit)` is also true of NaN. The time stamp is part of the reading (the fades' and the
  // timing guidance's clock).
  if (!(device.position_m.array().abs() <= kMaxDeviceReadingM).all() || !device.velocity_m_s.allFinite() ||
      !std::isfinite(device.time_s)) {
    out.input_rejected = true;
    command(Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), out);
    return out;
  }
  const Vec2 tip = device.position_m.head<2>();
  const double paper_z = scene_->layout.paper_z_m;
  const std::size_t character_before = active_.character_index();
  const std::size_t stroke_before = active_.stroke_index();
  const std::size_t element_before = active_.element_index();
  const InteractionState state_before = state_;
  const bool finished_before = active_.finished();

  StateInputs inputs;
  const double release_z =
      paper_z + (state_ == InteractionState::separation ? 0.0 : parameters_.contact_hysteresis_m);
  inputs.touching = device.position_m.z() <= release_z;
  if (const PlacedCharacter* c = active_.character()) inputs.inside_box = c->bounding_box.contains(tip);
  if (const PlacedStroke* s = active_.stroke()) {
    inputs.in_start_neighbourhood = (tip - s->start()).norm() <= scene_->layout.start_radius_m;
  }
  InteractionState next = next_state(state_, inputs);
  // The pen-down as a whole, from touch-down to lift: its path decides whether a refusal is a miss.
  if (next != InteractionState::separation) {
    if (state_ == InteractionState::separation) {
      contact_ = RefusedPenDown{};
      contact_tip_m_ = tip;
    }
    contact_.path_m += (tip - contact_tip_m_).norm();
    contact_tip_m_ = tip;
    ++contact_.samples;
    contact_.entered_ws = contact_.entered_ws || next == InteractionState::writing;
    contact_.in_character_box = contact_.in_character_box || inputs.inside_box;
  }
  if (state_ == InteractionState::writing && next == InteractionState::separation) {
    // Lifting in WS ends the attempt: written when it reached the end neighbourhood, else abandoned and
    // the stroke's feature points reloaded (section 4.3.3).
    const StrokeProgress lifted = active_.lift(active_.acceptance().counts_as_miss(contact_));
    out.stroke_completed = lifted.stroke_completed;
    out.stroke_abandoned = !lifted.stroke_completed;
    out.refusal = lifted.refusal;
    out.stroke_assisted = lifted.stroke_assisted;
  } else if (state_ != InteractionState::separation && next == InteractionState::separation &&
             !contact_.entered_ws && !active_.finished() && active_.acceptance().counts_as_miss(contact_)) {
    // A pen-down that never came near the stroke's start (written beside it, or another stroke) is a miss
    // too, so that a learner who never finds the start is hinted and credited (no dead end).
    const StrokeProgress missed = active_.miss();
    out.missed_off_start = true;
    out.refusal = missed.refusal;
    out.stroke_assisted = missed.stroke_assisted;
  }
  if (next == InteractionState::writing) {
    if (state_ != InteractionState::writing) active_.begin(tip);
    if (active_.advance(tip).stroke_completed) {
      out.stroke_completed = true;
      next = InteractionState::calibration;  // written; the next stroke starts at its own neighbourhood
    }
  }
  if (next == InteractionState::writing && state_ != InteractionState::writing)
    writing_since_s_ = device.time_s;
  out.state_changed = next != state_;
  state_ = next;
  const bool writing = state_ == InteractionState::writing && !active_.finished();
  const bool element_changed =
      active_.character_index() != character_before || active_.stroke_index() != stroke_before ||
      active_.element_index() != element_before ||
      (state_ == InteractionState::writing) != (state_before == InteractionState::writing);

  // Paper force, eq. (9), with inward-only damping; faded in when the paper starts pushing on a tip
  // that is already below it (AS -> CS) and out when it stops (CS -> AS), section 6.
  const bool paper_on = state_ == InteractionState::calibration || state_ == InteractionState::writing;
  if (state_before == InteractionState::separation || parameters_.paper_fade_s <= 0.0) {
    paper_weight_ = paper_on ? 1.0 : 0.0;  // a touch-down starts at zero depth: no step to smooth
  } else {
    const double step = period_s_ / parameters_.paper_fade_s;
    paper_weight_ = paper_on ? std::min(1.0, paper_weight_ + step) : std::max(0.0, paper_weight_ - step);
  }
  Vec3 force = paper_force(device.position_m.z(), paper_z, parameters_.paper_stiffness_n_per_m);
  if (force.z() > 0.0 && device.velocity_m_s.z() < 0.0) {
    force.z() -= parameters_.paper_damping_n_s_per_m * device.velocity_m_s.z();
  }
  force *= paper_weight_;

  // In-plane guidance, cross-faded when its source changes (element, stroke, character, WS, CS, inside).
  Vec2 target = Vec2::Zero();
  const double slack = writing ? corner_slack(active_, tip, parameters_.constraint_radius_m) : 0.0;
  if (writing) {
    target = guidance_force(device, out, element_changed, slack);
  } else {
    foot_valid_ = false;
  }
  // Off-stroke resistance: in CS a friction against any in-plane motion; in WS outside the active
  // element's constraint space a damper against motion away from the element (a stroke that set off
  // from the active start in another direction), never against coming back to it.
  off_stroke_velocity_ += off_stroke_alpha_ * (device.velocity_m_s.head<2>() - off_stroke_velocity_);
  const bool off_in_calibration = state_ == InteractionState::calibration;
  // Past the end of the stroke (its last element's end plane, eq. 6) the pen is finishing, not leaving
  // the stroke: nothing resists it or pulls it back to the end (docs/stroke-acceptance.md).
  const auto beyond_end = [&] {
    const PlacedStroke* s = active_.stroke();
    return s != nullptr &&
           (active_.attempt().passed_end() || (active_.element_index() + 1 == s->elements.size() &&
                                               feature_plane_passed(s->elements.back(), tip)));
  };
  const bool off_in_writing = writing && !out.in_constraint_space && !beyond_end();
  if (!off_in_calibration) anchor_valid_ = false;
  if (parameters_.guidance && off_in_calibration) {
    if (!anchor_valid_) off_stroke_anchor_ = tip;  // adheres where CS was entered
    anchor_valid_ = true;
    target = off_stroke_friction(tip, off_stroke_anchor_, parameters_.off_stroke_force_n,
                                 parameters_.off_stroke_travel_m);
  } else if (parameters_.guidance && off_in_writing) {
    const Vec2 away = tip - out.foot_m;
    const double distance = away.norm();
    const double outward = distance > 0.0 ? std::max(0.0, off_stroke_velocity_.dot(away) / distance) : 0.0;
    if (outward > 0.0) {
      target = (1.0 - slack) * off_stroke_resistance(outward * away / distance,
                                                     parameters_.off_stroke_damping_n_s_per_m,
                                                     parameters_.off_stroke_speed_m_s);
    }
  }
  const bool off_stroke_changed = off_in_calibration != (state_before == InteractionState::calibration);
  if (element_changed || off_stroke_changed || out.in_constraint_space != was_inside_) {
    fade_from_ = guidance_;
    fade_elapsed_s_ = 0.0;
  }
  was_inside_ = out.in_constraint_space;
  fade_elapsed_s_ += period_s_;
  const double blend =
      parameters_.crossfade_s > 0.0 ? smoothstep(fade_elapsed_s_ / parameters_.crossfade_s) : 1.0;
  guidance_ = fade_from_ + blend * (target - fade_from_);
  force.head<2>() += guidance_;

  // Paper friction (Coulomb with a stick band), against the in-plane velocity.
  force.head<2>() += friction_force(device.velocity_m_s.head<2>(), force.z(),
                                    parameters_.friction_coefficient, parameters_.friction_stick_speed_m_s);

  if (options_.passivity.enabled) {
    force = passivity_.apply(device.position_m, device.velocity_m_s, chain_.last_output(), force);
    out.passivity_damping_n_s_per_m = passivity_.damping_n_s_per_m();
  }
  // Every stroke written by an earlier tick: nothing is left to guide, and the paper's force goes too
  // (docs/force-rendering.md); the safety chain takes the force down to zero at its per-tick rate. The tick
  // that wrote the last stroke keeps its force, the last of the trial.
  if (finished_before) force = Vec3::Zero();
  out.force_error = !force.allFinite();
  command(force, out);
  return out;
}

// The force law's force through the safety chain into `out`, with where the renderer now stands.
void Renderer::command(const Vec3& force, RenderOutput& out) noexcept {
  const SafetyResult safe = chain_.apply(force);
  out.force_n = safe.force_n;
  out.limits = safe.limits;
  out.state = state_;
  out.finished = active_.finished();
  out.character = active_.character_index();
  out.stroke = active_.stroke_index();
  out.misses = active_.misses();
  out.hint_shown = active_.hint_shown();
  out.element = active_.element_index();
}

}  // namespace calligraphy
