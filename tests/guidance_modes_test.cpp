// Guidance modes of the renderer (guidance_mode.hpp, teacher_replay.hpp): fading scales F_et by its
// gain, the performance rule moves the gain, replay turns a teacher's trial into a moving attraction
// point, and the off-stroke resistance opposes writing outside the active stroke under guidance.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/render/teacher_replay.hpp"
#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

// Single ticks show the force law exactly: no smoothing, ramp or rate limit, no friction.
ForceLawParameters exact() {
  ForceLawParameters p;
  p.constraint_taper_m = 0.0;
  p.crossfade_s = 0.0;
  p.paper_fade_s = 0.0;
  p.friction_coefficient = 0.0;
  p.max_foot_speed_m_s = 1e6;
  return p;
}

RendererOptions exact_options() {
  RendererOptions o;
  o.safety.start_ramp_n_per_s = 0.0;
  o.safety.max_force_change_n_per_tick = 0.0;
  return o;
}

// In-plane force with the pen in WS at data x = 400, 30 data units (1.76 mm) above the 横.
Vec2 guidance_at_offset(const ForceLawParameters& force) {
  const Scene scene = horizontal_stroke_scene();
  Renderer r(scene, force, simulated_phantom_desktop_info(), exact_options());
  const double z = scene.layout.paper_z_m - 0.0005;
  r.tick(device_state_at(scene, {205, 600}, z));  // touch down at the start: WS
  const RenderOutput out = r.tick(device_state_at(scene, {400, 630}, z));
  REQUIRE(out.state == InteractionState::writing);
  return out.force_n.head<2>();
}

// A synthetic teacher on the 横: touch down at the start at t = 1 s, move right at 50 mm/s to the end,
// lift. Device frame [m].
std::vector<TeacherSample> straight_teacher(const Scene& scene, double hold_at_data_x = -1.0,
                                            double hold_s = 0.0) {
  const Placement& placement = scene.characters[0].placement;
  const double z_down = scene.layout.paper_z_m - 0.0005;
  const double z_up = scene.layout.paper_z_m + 0.005;
  std::vector<TeacherSample> samples;
  const auto add = [&](double t, double data_x, double z) {
    const Vec2 p = placement.to_paper({data_x, 600.0});
    samples.push_back(TeacherSample{t, Vec3(p.x(), p.y(), z)});
  };
  add(0.0, 200.0, z_up);
  add(1.0, 200.0, z_down);
  const double metres_per_unit = placement.metres_per_unit;
  double t = 1.0;
  for (double x = 200.0; x <= 830.0; x += 5.0) {
    add(t, x, z_down);
    t += 5.0 * metres_per_unit / 0.05;
    if (hold_at_data_x > 0.0 && std::abs(x - hold_at_data_x) < 2.5) t += hold_s;
  }
  add(t + 0.2, 830.0, z_up);
  return samples;
}

}  // namespace

TEST_CASE("Guidance modes have names", "[guidance]") {
  for (const GuidanceMode mode : {GuidanceMode::fixed, GuidanceMode::fading, GuidanceMode::replay}) {
    CHECK(guidance_mode_from_string(to_string(mode)) == mode);
  }
  CHECK_FALSE(guidance_mode_from_string("haptic").has_value());
}

TEST_CASE("Fading scales F_et by its gain and the fixed mode ignores the gain", "[guidance]") {
  ForceLawParameters fixed = exact();
  fixed.resistance_damping_n_s_per_m = 0.0;
  const Vec2 full = guidance_at_offset(fixed);
  REQUIRE(full.norm() > 0.1);
  ForceLawParameters fading = fixed;
  fading.guidance_law = default_guidance_law(GuidanceMode::fading);
  for (const double gain : {0.0, 0.25, 0.5, 1.0}) {
    std::get<FadingGuidance>(fading.guidance_law).gain = gain;
    const Vec2 faded = guidance_at_offset(fading);
    CHECK(faded.x() == Approx(gain * full.x()).margin(1e-12));
    CHECK(faded.y() == Approx(gain * full.y()).margin(1e-12));
  }
  // A fixed law has no gain to apply: the paper's fixture at full strength.
  CHECK(guidance_at_offset(fixed).y() == Approx(full.y()));
}

TEST_CASE("The guidance gain and the fading rule are validated", "[guidance]") {
  ForceLawParameters p;
  p.guidance_law = FadingGuidance{.gain = 1.5};
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("FadingGuidance.gain"));
  p.guidance_law = FadingGuidance{.gain = -0.1};
  CHECK_THROWS_AS(p.validate(), InvalidArgument);
  CHECK_THROWS_WITH(next_guidance_gain(1.2, 0.0), Catch::Contains("gain"));
  CHECK_THROWS_WITH(next_guidance_gain(0.5, -1e-3), Catch::Contains("error_m"));
  FadingRule rule;
  rule.forgetting_factor = 1.5;
  CHECK_THROWS_WITH(next_guidance_gain(0.5, 0.0, rule), Catch::Contains("forgetting_factor"));
}

TEST_CASE("The fading rule lowers the gain when the trainee does well and raises it on errors",
          "[guidance]") {
  const FadingRule rule;  // f = 0.8, k = 200 / m
  double gain = 1.0;
  for (int repetition = 0; repetition < 10; ++repetition) {
    const double next = next_guidance_gain(gain, 0.0, rule);
    CHECK(next < gain);
    gain = next;
  }
  CHECK(gain == Approx(std::pow(0.8, 10)));
  CHECK(next_guidance_gain(0.2, 2e-3, rule) > 0.2);   // 2 mm of error brings guidance back
  CHECK(next_guidance_gain(0.9, 0.05, rule) == 1.0);  // and never beyond 1
}

TEST_CASE("A teacher's trial gives one window per stroke, read with the renderer's rules", "[guidance]") {
  const Scene scene = scene_of(U'十');
  WriterTrialOptions teacher;
  teacher.writer = WriterProfile::skilled();
  teacher.seed = 3;
  const WriterTrial recorded = run_writer_trial(scene, teacher);
  REQUIRE(recorded.metrics.completed_in_order);
  std::vector<TeacherSample> samples;
  for (const TrialSample& s : recorded.trace) samples.push_back(TeacherSample{s.time_s, s.position_m});
  const TeacherReplay replay(scene, samples, ForceLawParameters{});
  REQUIRE(replay.stroke_count() == scene.stroke_count());
  for (std::size_t k = 0; k < replay.stroke_count(); ++k) {
    INFO("stroke " << k);
    CHECK(replay.stroke_begin_s(k) < replay.stroke_end_s(k));
    if (k > 0) CHECK(replay.stroke_begin_s(k) > replay.stroke_end_s(k - 1));
    // The window is the recorder's: from entering WS to the lift that wrote the stroke.
    const StrokeMetrics& m = recorded.metrics.per_stroke[k];
    CHECK(replay.stroke_end_s(k) - replay.stroke_begin_s(k) == Approx(m.time_s).margin(2e-3));
    const PlacedStroke& stroke = scene.characters[0].strokes[k];
    CHECK((replay.position(k, 0.0) - stroke.start()).norm() <= scene.layout.start_radius_m);
    // Clamped to the window's end: the lift, within the end neighbourhood.
    CHECK((replay.position(k, 1e3) - stroke.end()).norm() <=
          ForceLawParameters{}.acceptance.follow_through_m);
  }
}

TEST_CASE("A bad teacher trajectory is refused naming the sample or the stroke", "[guidance]") {
  const Scene scene = horizontal_stroke_scene();
  std::vector<TeacherSample> samples = straight_teacher(scene);
  CHECK_NOTHROW(TeacherReplay(scene, samples, ForceLawParameters{}));
  std::vector<TeacherSample> backwards_in_time = samples;
  backwards_in_time[5].time_s = backwards_in_time[4].time_s - 0.1;
  CHECK_THROWS_WITH(TeacherReplay(scene, backwards_in_time, ForceLawParameters{}),
                    Catch::Contains("sample 5"));
  std::vector<TeacherSample> not_finite = samples;
  not_finite[3].position_m.x() = std::nan("");
  CHECK_THROWS_WITH(TeacherReplay(scene, not_finite, ForceLawParameters{}), Catch::Contains("sample 3"));
  const std::vector<TeacherSample> short_of_the_end(samples.begin(), samples.begin() + 60);
  CHECK_THROWS_WITH(TeacherReplay(scene, short_of_the_end, ForceLawParameters{}),
                    Catch::Contains("stroke 0"));
  ForceLawParameters replay;
  replay.guidance_law = default_guidance_law(GuidanceMode::replay);  // without a trajectory
  CHECK_THROWS_AS(Renderer(scene, replay, simulated_phantom_desktop_info()), InvalidArgument);
}

TEST_CASE("In the replay mode the attraction point moves at the teacher's pace", "[guidance]") {
  const Scene scene = horizontal_stroke_scene();
  ForceLawParameters force = exact();
  force.guidance_law = default_guidance_law(GuidanceMode::replay);
  std::get<ReplayGuidance>(force.guidance_law).teacher_trajectory = straight_teacher(scene);
  Renderer r(scene, force, simulated_phantom_desktop_info(), exact_options());
  const double z = scene.layout.paper_z_m - 0.0005;
  const double entered = 10.0;
  r.tick(device_state_at(scene, {200, 600}, z, entered));  // WS at the start; the replay clock starts
  // The pen stays at the start; the teacher moves right at 50 mm/s, so the pull along +x grows as
  // 50 mm/s * t * K_et until the spring saturates at K_et max_lead_m (3 mm: after 60 ms).
  double previous = 0.0;
  for (const double t : {0.02, 0.04, 0.05, 0.07}) {
    const RenderOutput out = r.tick(device_state_at(scene, {200, 600}, z, entered + t));
    REQUIRE(out.state == InteractionState::writing);
    const double expected = force.guidance_stiffness_n_per_m *
                            std::min(0.05 * t, std::get<ReplayGuidance>(force.guidance_law).max_lead_m);
    CHECK(out.force_n.x() >= previous);
    CHECK(out.force_n.x() == Approx(expected).epsilon(0.1));
    CHECK(std::abs(out.force_n.y()) < 1e-6);
    previous = out.force_n.x();
  }
  const RenderOutput late = r.tick(device_state_at(scene, {200, 600}, z, entered + 5.0));
  CHECK(late.force_n.head<2>().norm() <= force.guidance_stiffness_n_per_m *
                                             std::get<ReplayGuidance>(force.guidance_law).max_lead_m *
                                             (1.0 + 1e-9));
}

TEST_CASE("Off-stroke resistance: friction in CS, a damper on leaving the element in WS, under guidance only",
          "[guidance]") {
  const Scene scene = horizontal_stroke_scene();
  const double z = scene.layout.paper_z_m - 0.0005;
  const double metres_per_unit = scene.characters[0].placement.metres_per_unit;
  ForceLawParameters force = exact();
  for (const bool guidance : {true, false}) {
    force.guidance = guidance;
    Renderer r(scene, force, simulated_phantom_desktop_info(), exact_options());
    // Touch down in CS, away from the start, and slide +y by 0.25 mm per tick.
    RenderOutput out = r.tick(device_state_at(scene, {500, 560}, z));
    REQUIRE(out.state == InteractionState::calibration);
    CHECK(out.force_n.head<2>().norm() < 1e-12);  // held where it touched down
    out = r.tick(device_state_at(scene, {500, 560 + 0.0005 / metres_per_unit}, z, 1e-3));
    if (guidance) {
      CHECK(out.force_n.y() == Approx(-0.5 * force.off_stroke_force_n));  // half the travel: half the force
    }
    for (int k = 2; k < 10; ++k)
      out = r.tick(device_state_at(scene, {500, 560 + 0.00025 * k / metres_per_unit}, z, 1e-3 * k));
    REQUIRE(out.state == InteractionState::calibration);
    if (guidance) {
      CHECK(out.force_n.y() == Approx(-force.off_stroke_force_n));  // dragged: the full force, at any speed
      CHECK(std::abs(out.force_n.x()) < 1e-9);
    } else {
      CHECK(out.force_n.head<2>().norm() < 1e-9);
    }
  }
  Vec2 anchor(0.0, 0.0);
  CHECK(off_stroke_friction(Vec2(0.0005, 0.0), anchor, 0.5, 0.001).x() == Approx(-0.25));
  CHECK(off_stroke_friction(Vec2(0.003, 0.0), anchor, 0.5, 0.001).x() == Approx(-0.5));
  CHECK(anchor.x() == Approx(0.002));
  CHECK(off_stroke_resistance(Vec2(0.004, 0.0), 40.0, 0.005).norm() == 0.0);  // below the threshold speed
  CHECK(off_stroke_resistance(Vec2(0.01, 0.0), 40.0, 0.005).x() == Approx(-0.4));
}

TEST_CASE("A novice guided by a skilled teacher's replay writes every stroke in order", "[guidance]") {
  const Scene scene = scene_of(U'口');
  WriterTrialOptions teacher;
  teacher.writer = WriterProfile::skilled();
  teacher.seed = 11;
  const WriterTrial recorded = run_writer_trial(scene, teacher);
  REQUIRE(recorded.metrics.completed_in_order);
  WriterTrialOptions student;
  student.seed = 4;
  student.force.guidance_law = default_guidance_law(GuidanceMode::replay);
  for (const TrialSample& s : recorded.trace)
    std::get<ReplayGuidance>(student.force.guidance_law)
        .teacher_trajectory.push_back({s.time_s, s.position_m});
  const WriterTrial replayed = run_writer_trial(scene, student);
  CHECK(replayed.metrics.completed_in_order);
  WriterTrialOptions unguided = student;
  unguided.force.guidance = false;
  const WriterTrial alone = run_writer_trial(scene, unguided);
  CHECK(replayed.metrics.mean_deviation_m < alone.metrics.mean_deviation_m);
}
