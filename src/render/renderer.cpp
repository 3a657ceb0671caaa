#include "calligraphy/renderer.hpp"

#include <spdlog/spdlog.h>

#include <string>

#include "calligraphy/constraint_space.hpp"
#include "calligraphy/errors.hpp"

namespace calligraphy {

Renderer::Renderer(const Scene& scene, const ForceLawParameters& parameters, const DeviceInfo& device)
    : scene_(&scene), parameters_(parameters), max_force_n_(device.max_force_n), active_(scene) {
  parameters_.validate();
  if (!(max_force_n_ > 0.0)) {
    throw InvalidArgument("Renderer: device '" + device.model + "' max_force_n = " + std::to_string(max_force_n_) +
                          " must be > 0");
  }
  const double k_max = device.max_stiffness_n_per_m;
  if (k_max > 0.0 && (parameters_.paper_stiffness_n_per_m > k_max || parameters_.guidance_stiffness_n_per_m > k_max)) {
    spdlog::warn("stiffness above the device's stable maximum of {} N/m ({}): paper {} N/m, guidance {} N/m", k_max,
                 device.model, parameters_.paper_stiffness_n_per_m, parameters_.guidance_stiffness_n_per_m);
  }
}

void Renderer::reset() noexcept {
  active_.reset();
  state_ = InteractionState::separation;
}

RenderOutput Renderer::tick(const DeviceState& device) noexcept {
  RenderOutput out;
  if (!device.position_m.allFinite() || !device.velocity_m_s.allFinite()) {
    out.input_rejected = true;
    out.state = state_;
    out.finished = active_.finished();
    return out;
  }
  const Vec2 tip = device.position_m.head<2>();
  const double paper_z = scene_->layout.paper_z_m;

  StateInputs inputs;
  const double release_z =
      paper_z + (state_ == InteractionState::separation ? 0.0 : parameters_.contact_hysteresis_m);
  inputs.touching = device.position_m.z() <= release_z;
  if (const PlacedCharacter* c = active_.character()) inputs.inside_box = c->bounding_box.contains(tip);
  if (const PlacedStroke* s = active_.stroke()) {
    inputs.in_start_neighbourhood = (tip - s->start()).norm() <= scene_->layout.start_radius_m;
  }
  InteractionState next = next_state(state_, inputs);
  if (state_ == InteractionState::writing && next == InteractionState::separation) {
    active_.reload();  // lifting in WS abandons the stroke (section 4.3.3)
    out.stroke_abandoned = true;
  }
  if (next == InteractionState::writing) {
    if (active_.advance(tip).stroke_completed) {
      out.stroke_completed = true;
      next = InteractionState::calibration;  // written; the next stroke starts at its own neighbourhood
    }
  }
  out.state_changed = next != state_;
  state_ = next;

  Vec3 force = Vec3::Zero();
  if (state_ == InteractionState::calibration || state_ == InteractionState::writing) {
    force += paper_force(device.position_m.z(), paper_z, parameters_.paper_stiffness_n_per_m);
  }
  if (state_ == InteractionState::writing && !active_.finished()) {
    const StrokeElement& element = *active_.element();
    const ElementContact contact =
        element_contact(element, tip, parameters_.constraint_radius_m, parameters_.nearest);
    out.in_constraint_space = contact.inside;
    out.foot_m = contact.nearest.foot;
    if (parameters_.guidance && contact.inside) {
      const Vec2 tangent = element.unit_tangent(contact.nearest.t);
      const Vec2 in_plane = attraction_force(tip, contact.nearest.foot, parameters_.guidance_stiffness_n_per_m,
                                             active_.attraction(contact.nearest.t)) +
                            resistance_force(device.velocity_m_s.head<2>(), tangent,
                                             parameters_.resistance_damping_n_s_per_m);
      force.head<2>() += in_plane;
    }
  }
  out.force_n = clamp_force(force, max_force_n_);
  out.state = state_;
  out.finished = active_.finished();
  out.character = active_.character_index();
  out.stroke = active_.stroke_index();
  out.element = active_.element_index();
  return out;
}

}  // namespace calligraphy
