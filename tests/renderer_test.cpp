#include "calligraphy/render/renderer.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "calligraphy/devices/simulated_device.hpp"

using namespace calligraphy;

namespace {

// One character: stroke 0 is a 横折 (right, then down), stroke 1 a 横 lower down. Data units.
Scene two_stroke_scene() {
  Character c;
  c.code_point = U'口';
  Stroke hz;
  hz.typical_id = 7;
  hz.elements = {StrokeElement::line({200, 600}, {800, 600}), StrokeElement::line({800, 600}, {800, 100})};
  hz.attraction_factors = {1.0, 2.0, 2.0};
  Stroke h;
  h.typical_id = 1;
  h.elements = {StrokeElement::line({200, 300}, {700, 300})};
  h.attraction_factors = {1.0, 1.0};
  c.strokes = {hz, h};
  return Scene::lay_out({c});
}

DeviceState at(const Scene& scene, const Vec2& data, double z, const Vec2& velocity = Vec2::Zero()) {
  DeviceState s;
  const Vec2 p = scene.characters[0].placement.to_paper(data);
  s.position_m = Vec3(p.x(), p.y(), z);
  s.velocity_m_s = Vec3(velocity.x(), velocity.y(), 0.0);
  return s;
}

// The paper's force law without the smoothing of section 6 and without the safety chain's ramp and
// rate limit, so that single ticks show eqs. (7)-(9) exactly (the smoothing is tested in
// smoothness_test.cpp).
ForceLawParameters unsmoothed() {
  ForceLawParameters p;
  p.constraint_taper_m = 0.0;
  p.crossfade_s = 0.0;
  p.paper_fade_s = 0.0;
  p.friction_coefficient = 0.0;
  p.max_foot_speed_m_s = 1e6;
  return p;
}

// The pen moved from `from` to `to` (data units) in steps of one data unit (0.06 mm), one tick each, as a
// hand moves it: progress along a stroke is credited only for continuous forward motion.
RenderOutput glide(Renderer& r, const Scene& scene, const Vec2& from, const Vec2& to, double z) {
  const int steps = std::max(1, static_cast<int>(std::ceil((to - from).norm())));
  RenderOutput out;
  for (int i = 1; i <= steps; ++i)
    out = r.tick(at(scene, from + (to - from) * (static_cast<double>(i) / steps), z));
  return out;
}

RendererOptions no_ramp_no_rate_limit() {
  RendererOptions o;
  o.safety.start_ramp_n_per_s = 0.0;
  o.safety.max_force_change_n_per_tick = 0.0;
  return o;
}

}  // namespace

TEST_CASE("Renderer: states, plane popping, completion and per-state forces", "[renderer]") {
  const Scene scene = two_stroke_scene();
  Renderer r(scene, unsmoothed(), simulated_phantom_desktop_info(), no_ramp_no_rate_limit());
  const double below = -0.001;  // 1 mm into the paper

  // SS above the paper: zero force.
  auto out = r.tick(at(scene, {500, 500}, 0.01));
  CHECK(out.state == InteractionState::separation);
  CHECK(out.force_n.isZero());
  // AS: touching outside the bounding box: zero force (Table 2).
  out = r.tick(at(scene, {1000, -100}, below));
  CHECK(out.state == InteractionState::adjusting);
  CHECK(out.force_n.isZero());
  // CS: inside the box, away from the start: only the normal force.
  out = r.tick(at(scene, {500, 450}, below));
  CHECK(out.state == InteractionState::calibration);
  CHECK(out.force_n.head<2>().isZero());
  CHECK(out.force_n.z() == Approx(0.8));  // 800 N/m * 1 mm
  // WS: at the start point.
  out = r.tick(at(scene, {210, 600}, below));
  CHECK(out.state == InteractionState::writing);
  CHECK(out.element == 0);
  // Off the stroke by 40 data units (2.34 mm): attraction back towards it, in -y.
  glide(r, scene, {210, 600}, {490, 640}, below);
  out = r.tick(at(scene, {500, 640}, below));
  CHECK(out.in_constraint_space);
  const double offset_m = 40 * 0.06 / 1024;
  // Halfway along the element the attraction factor is 1.5, between its feature points' 1 and 2.
  CHECK(out.force_n.y() == Approx(-400.0 * 1.5 * offset_m).epsilon(1e-9));
  CHECK(out.force_n.x() == Approx(0.0).margin(1e-12));
  // Moving backwards along the element: resistance pushes forward (+x).
  glide(r, scene, {500, 640}, {510, 600}, below);
  out = r.tick(at(scene, {500, 600}, below, Vec2(-0.02, 0.0)));
  CHECK(out.force_n.x() == Approx(15.0 * 0.02));
  // Going round the corner at (800, 600), cutting it 10 units inside, pops to the vertical element: the
  // pen never crosses the feature plane x = 800.
  glide(r, scene, {500, 600}, {780, 600}, below);
  out = glide(r, scene, {780, 600}, {790, 560}, below);
  CHECK(out.element == 1);
  CHECK(out.stroke == 0);
  // Lifting mid-stroke abandons it as too short: the feature points are reloaded.
  glide(r, scene, {790, 560}, {795, 400}, below);
  out = r.tick(at(scene, {795, 400}, 0.01));
  CHECK(out.state == InteractionState::separation);
  CHECK(out.stroke_abandoned);
  CHECK(out.refusal == StrokeRefusal::too_short);
  CHECK(r.active().element_index() == 0);
  CHECK(r.active().stroke_index() == 0);
  // Write it again and lift 30 units (1.8 mm) short of the end: the stroke completes at the lift.
  r.tick(at(scene, {200, 600}, below));
  glide(r, scene, {200, 600}, {800, 600}, below);
  out = glide(r, scene, {800, 600}, {800, 130}, below);
  CHECK(out.state == InteractionState::writing);
  CHECK_FALSE(out.stroke_completed);
  out = r.tick(at(scene, {800, 130}, 0.01));
  CHECK(out.stroke_completed);
  CHECK_FALSE(out.stroke_abandoned);
  CHECK(out.state == InteractionState::separation);
  CHECK(out.stroke == 1);
  CHECK(r.active().strokes_written() == 1);
  // The written stroke is not written again: touching its start now is plain CS.
  out = r.tick(at(scene, {200, 600}, below));
  CHECK(out.state == InteractionState::calibration);
  // The next stroke starts at its own neighbourhood; carried 20 units past its end the pen is left alone
  // (no in-plane guidance back to the end), and the lift writes it.
  out = r.tick(at(scene, {200, 300}, 0.01));
  out = r.tick(at(scene, {200, 300}, below));
  CHECK(out.state == InteractionState::writing);
  out = glide(r, scene, {200, 300}, {720, 300}, below);
  CHECK(out.state == InteractionState::writing);
  CHECK_FALSE(out.in_constraint_space);
  CHECK(out.force_n.head<2>().isZero());
  out = r.tick(at(scene, {720, 300}, 0.01));
  CHECK(out.stroke_completed);
  CHECK(out.finished);
}

TEST_CASE("Renderer: a pen that passes the end and leaves the end neighbourhood loses the stroke",
          "[renderer]") {
  const Scene scene = two_stroke_scene();
  Renderer r(scene, unsmoothed(), simulated_phantom_desktop_info(), no_ramp_no_rate_limit());
  const double below = -0.001;
  r.tick(at(scene, {200, 600}, below));
  glide(r, scene, {200, 600}, {800, 600}, below);
  glide(r, scene, {800, 600}, {800, 100}, below);
  // On into the next stroke's region without lifting: 10 mm from the end.
  glide(r, scene, {800, 100}, {630, 100}, below);
  const RenderOutput out = r.tick(at(scene, {630, 100}, 0.01));
  CHECK(out.stroke_abandoned);
  CHECK_FALSE(out.stroke_completed);
  CHECK(out.refusal == StrokeRefusal::wrong_stroke);
  CHECK(r.active().strokes_written() == 0);
}

TEST_CASE("Renderer: non-finite input gives zero force, never NaN", "[renderer]") {
  const Scene scene = two_stroke_scene();
  Renderer r(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  DeviceState s = at(scene, {210, 600}, -0.001);
  s.position_m.x() = std::numeric_limits<double>::quiet_NaN();
  const auto out = r.tick(s);
  CHECK(out.input_rejected);
  CHECK(out.force_n.isZero());
}

TEST_CASE("Renderer: a reading beyond any device's reach is rejected like a non-finite one", "[renderer]") {
  const Scene scene = two_stroke_scene();
  Renderer r(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  DeviceState s = at(scene, {210, 600}, -0.001);
  const auto near = r.tick(s);
  CHECK_FALSE(near.input_rejected);
  // A garbled driver value: finite, but no pen on a desk.
  s.position_m.y() = 1e304;
  const auto far = r.tick(s);
  CHECK(far.input_rejected);
  CHECK(far.force_n.isZero());
  s.position_m.y() = -2.0 * kMaxDeviceReadingM;
  CHECK(r.tick(s).input_rejected);
}

TEST_CASE("Renderer: guidance off keeps the paper and the tracking but no in-plane force", "[renderer]") {
  const Scene scene = two_stroke_scene();
  ForceLawParameters p;
  p.guidance = false;
  Renderer r(scene, p, simulated_phantom_desktop_info());
  r.tick(at(scene, {210, 600}, -0.001));
  const auto out = r.tick(at(scene, {500, 640}, -0.001));
  CHECK(out.state == InteractionState::writing);
  CHECK(out.force_n.head<2>().isZero());
  CHECK(out.force_n.z() > 0.0);
}

TEST_CASE("Renderer: the force never exceeds the device maximum", "[renderer]") {
  const Scene scene = two_stroke_scene();
  DeviceInfo weak = simulated_phantom_desktop_info();
  weak.max_force_n = 0.5;
  Renderer r(scene, unsmoothed(), weak, no_ramp_no_rate_limit());
  const auto out = r.tick(at(scene, {300, 500}, -0.01));  // 10 mm deep: 8 N asked
  CHECK(out.force_n.norm() == Approx(0.5));
}

TEST_CASE("Renderer: a peak or continuous force given above the device's is taken as the device's",
          "[renderer]") {
  const Scene scene = two_stroke_scene();
  DeviceInfo weak = simulated_phantom_desktop_info();
  weak.max_force_n = 0.5;
  weak.max_continuous_force_n = 0.4;
  RendererOptions options = no_ramp_no_rate_limit();
  options.safety.max_force_n = 20.0;  // within the chain's own range (100 N), far above this device
  Renderer r(scene, unsmoothed(), weak, options);
  const auto out = r.tick(at(scene, {300, 500}, -0.01));  // 10 mm deep: 8 N asked
  CHECK(out.force_n.norm() == Approx(0.5));
  CHECK(r.safety_chain().parameters().max_force_n == 0.5);
  CHECK(r.safety_chain().parameters().max_continuous_force_n == 0.4);

  options.safety.max_force_n = 0.3;  // one below the device's is kept, and the continuous force under it
  options.safety.max_continuous_force_n = 5.0;
  Renderer lower(scene, unsmoothed(), weak, options);
  CHECK(lower.tick(at(scene, {300, 500}, -0.01)).force_n.norm() == Approx(0.3));
  CHECK(lower.safety_chain().parameters().max_force_n == 0.3);
  CHECK(lower.safety_chain().parameters().max_continuous_force_n == 0.3);
}
