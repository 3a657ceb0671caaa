// The guidance schedules beside the paper's fixture (guidance_mode.hpp, timing_target.hpp): assist-as-needed
// acts beyond its band only, error amplification pushes off the stroke within its bound, timing guidance
// pulls along the stroke only, the band and skill-adaptive rules, and every schedule through whole trials on
// held-out characters within the force-step limit and the device's peak force.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/render/timing_target.hpp"
#include "test_sizing.hpp"
#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

// The force law alone: no smoothing, ramp, rate limit, friction or resistance.
ForceLawParameters exact(GuidanceMode mode) {
  ForceLawParameters p;
  p.guidance_law = default_guidance_law(mode);
  p.constraint_taper_m = 0.0;
  p.crossfade_s = 0.0;
  p.paper_fade_s = 0.0;
  p.friction_coefficient = 0.0;
  p.resistance_damping_n_s_per_m = 0.0;
  p.max_foot_speed_m_s = 1e6;
  return p;
}

// In-plane force with the pen in WS at data (x, 600 + offset), `elapsed_s` after touching down at the start.
Vec2 force_at(const ForceLawParameters& force, double x, double offset, double elapsed_s = 0.001) {
  const Scene scene = horizontal_stroke_scene();
  RendererOptions options;
  options.safety.start_ramp_n_per_s = 0.0;
  options.safety.max_force_change_n_per_tick = 0.0;
  Renderer r(scene, force, simulated_phantom_desktop_info(), options);
  const double z = scene.layout.paper_z_m - 0.0005;
  r.tick(device_state_at(scene, {205, 600}, z, 0.0));
  const RenderOutput out = r.tick(device_state_at(scene, {x, 600 + offset}, z, elapsed_s));
  REQUIRE(out.state == InteractionState::writing);
  return out.force_n.head<2>();
}

double metres_per_unit() { return horizontal_stroke_scene().characters[0].placement.metres_per_unit; }

}  // namespace

TEST_CASE("Every guidance mode has a name that reads back", "[guidance]") {
  REQUIRE(guidance_modes().size() == 6);
  for (const GuidanceMode mode : guidance_modes()) CHECK(guidance_mode_from_string(to_string(mode)) == mode);
  CHECK_FALSE(guidance_mode_from_string("amplification").has_value());
}

TEST_CASE("Assist-as-needed leaves the band to the writer and is continuous at its edge", "[guidance]") {
  const double offset_m = 30 * metres_per_unit();  // the pen 30 data units off the stroke
  const Vec2 fixed = force_at(exact(GuidanceMode::fixed), 400, 30);
  REQUIRE(fixed.norm() > 0.1);
  ForceLawParameters assist = exact(GuidanceMode::assist_as_needed);
  std::get<AssistAsNeededGuidance>(assist.guidance_law).band_m = 1.2 * offset_m;
  CHECK(force_at(assist, 400, 30).norm() == Approx(0.0).margin(1e-12));  // within the band
  for (const double share : {0.0, 0.25, 0.5, 0.999}) {
    std::get<AssistAsNeededGuidance>(assist.guidance_law).band_m = share * offset_m;
    const Vec2 f = force_at(assist, 400, 30);
    // K a (d - b): the fixture's force scaled by the deviation beyond the band, in the same direction.
    CHECK(f.y() == Approx((1.0 - share) * fixed.y()).margin(1e-9));
    CHECK(f.x() == Approx(0.0).margin(1e-9));
  }
}

TEST_CASE("Error amplification pushes off the stroke and stays within its bound", "[guidance]") {
  const Vec2 fixed = force_at(exact(GuidanceMode::fixed), 400, 30);
  ForceLawParameters amplify = exact(GuidanceMode::error_amplification);
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).max_force_n = 10.0;
  for (const double gain : {0.0, 0.25, 1.0}) {
    std::get<ErrorAmplificationGuidance>(amplify.guidance_law).gain = gain;
    const Vec2 f = force_at(amplify, 400, 30);
    CHECK(f.y() == Approx(-gain * fixed.y()).margin(1e-9));  // away from the stroke
  }
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).gain = 1.0;
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).max_force_n = 0.1;
  CHECK(force_at(amplify, 400, 30).norm() == Approx(0.1).epsilon(1e-9));
  // Below the stroke the push is downwards: the deviation's side.
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).max_force_n = 10.0;
  CHECK(force_at(amplify, 400, -30).y() < 0.0);
  CHECK(force_at(amplify, 400, 30).y() > 0.0);
}

TEST_CASE("Timing guidance pulls along the stroke only, towards a target that moves at its pace",
          "[guidance]") {
  ForceLawParameters timing = exact(GuidanceMode::timing);
  std::get<TimingGuidance>(timing.guidance_law).speed_m_s = 0.04;
  // Just after touch-down the target is at the start: a pen further on is pulled back along the stroke, never
  // sideways however far off it is.
  const Vec2 early = force_at(timing, 400, 30, 0.001);
  CHECK(early.x() < 0.0);
  CHECK(early.y() == Approx(0.0).margin(1e-12));
  // Long after, the target is at the end: the same pen is pulled forwards, at most K a d_max.
  const Vec2 late = force_at(timing, 400, 30, 100.0);
  CHECK(late.x() > 0.0);
  CHECK(late.y() == Approx(0.0).margin(1e-12));
  CHECK(late.norm() <=
        timing.guidance_stiffness_n_per_m * std::get<TimingGuidance>(timing.guidance_law).max_lead_m + 1e-12);
}

TEST_CASE("The timing target follows a minimum-jerk profile over the stroke's length at the mean speed",
          "[guidance]") {
  const Scene scene = horizontal_stroke_scene();
  const double length_m = 600 * metres_per_unit();
  const TimingTarget target(scene, 0.05);
  const double duration = target.duration_s(0);
  CHECK(duration == Approx(length_m / 0.05));
  CHECK(target.place(0, -1.0).parameter == Approx(0.0).margin(1e-12));
  CHECK(target.place(0, duration / 2).parameter == Approx(0.5).margin(1e-9));  // symmetric profile
  CHECK(target.place(0, duration * 2).parameter == Approx(1.0).margin(1e-12));
  // s(u) = 10 u^3 - 15 u^4 + 6 u^5 at u = 0.25.
  CHECK(target.place(0, duration / 4).parameter == Approx(10.0 / 64 - 15.0 / 256 + 6.0 / 1024).margin(1e-9));
  double previous = -1.0;
  for (int i = 0; i <= 20; ++i) {
    const double u = target.place(0, duration * i / 20.0).parameter;
    CHECK(u >= previous);
    previous = u;
  }
  CHECK_THROWS_AS(TimingTarget(scene, 0.0), InvalidArgument);
}

TEST_CASE("The assist band widens on small errors and narrows on large ones, within its limits",
          "[guidance]") {
  const AssistBandRule rule;
  CHECK(next_assist_band(0.001, 0.0005, rule) > 0.001);
  CHECK(next_assist_band(0.001, 0.003, rule) < 0.001);
  CHECK(next_assist_band(0.001, rule.target_error_m, rule) == Approx(0.001));
  CHECK(next_assist_band(rule.max_band_m, 0.0, rule) == rule.max_band_m);
  CHECK(next_assist_band(0.0, 0.05, rule) == rule.min_band_m);
  CHECK_THROWS_AS(next_assist_band(-0.001, 0.001, rule), InvalidArgument);
  CHECK_THROWS_AS(next_assist_band(0.001, std::nan(""), rule), InvalidArgument);
  AssistBandRule bad;
  bad.min_band_m = 0.003;
  bad.max_band_m = 0.001;
  CHECK_THROWS_WITH(next_assist_band(0.001, 0.001, bad), Catch::Contains("AssistBandRule.max_band_m"));
}

TEST_CASE("Skill-adaptive selection guides the less skilled and amplifies for the more skilled",
          "[guidance]") {
  const SkillAdaptiveRule rule;
  CHECK(skill_adaptive_mode(2.0 * rule.threshold_m, rule) == GuidanceMode::fixed);
  CHECK(skill_adaptive_mode(rule.threshold_m, rule) == GuidanceMode::fixed);
  CHECK(skill_adaptive_mode(0.5 * rule.threshold_m, rule) == GuidanceMode::error_amplification);
  CHECK(skill_adaptive_mode(std::nan(""), rule) == GuidanceMode::fixed);  // nothing written
  CHECK_THROWS_AS(skill_adaptive_mode(-0.001, rule), InvalidArgument);
  SkillAdaptiveRule bad;
  bad.threshold_m = 0.0;
  CHECK_THROWS_WITH(skill_adaptive_mode(0.001, bad), Catch::Contains("SkillAdaptiveRule.threshold_m"));
}

TEST_CASE("Every new schedule writes held-out characters within the force-step limit and the peak force",
          "[guidance][smoothness]") {
  // Held-out: every 7th character of the second half of the embedded set, none of which tuned any mode.
  const std::vector<char32_t> half = embedded_half(true);
  std::vector<char32_t> characters;
  for (std::size_t i = 3; i < half.size() && characters.size() < 3; i += 7) characters.push_back(half[i]);
  struct Case {
    char32_t character;
    GuidanceMode mode;
    double rate_hz;
  };
  std::vector<Case> cases;
  for (const char32_t c : characters) {
    for (const GuidanceMode mode :
         {GuidanceMode::assist_as_needed, GuidanceMode::error_amplification, GuidanceMode::timing}) {
      for (const double rate : {1000.0, 4000.0}) cases.push_back({c, mode, rate});
    }
  }
  const double peak_n = simulated_phantom_desktop_info().max_force_n;
  for (const Case& trial_case : sanitizer_subset(cases, 3, "character x new mode x rate")) {
    const Scene scene = scene_of(trial_case.character);
    WriterTrialOptions options;
    options.seed = 3;
    options.rate_hz = trial_case.rate_hz;
    options.force.guidance_law = default_guidance_law(trial_case.mode);
    if (auto* assist = std::get_if<AssistAsNeededGuidance>(&options.force.guidance_law))
      assist->band_m = 0.0015;
    // Twice the default gain: a harder push than the schedule uses.
    if (auto* amplify = std::get_if<ErrorAmplificationGuidance>(&options.force.guidance_law))
      amplify->gain = 0.5;
    options.safety.max_force_change_n_per_tick = 0.0;  // the smoothing alone
    const WriterTrial trial = run_writer_trial(scene, options);
    double max_step = 0.0;
    double max_force = 0.0;
    double max_in_plane_n = 0.0;
    bool finite = true;
    // The passivity observer's energy (Hannaford & Ryu 2002) of the in-plane force: the work the guidance
    // did on the pen, the force held over each tick times the displacement it acted on. A positive peak is
    // energy the field gave the hand beyond what it had taken.
    double produced_j = 0.0;
    double max_produced_j = 0.0;
    for (std::size_t k = 0; k < trial.trace.size(); ++k) {
      const TrialSample& sample = trial.trace[k];
      finite = finite && sample.force_n.allFinite();
      max_force = std::max(max_force, sample.force_n.norm());
      max_in_plane_n = std::max(max_in_plane_n, sample.force_n.head<2>().norm());
      if (k > 0) {
        const TrialSample& before = trial.trace[k - 1];
        max_step = std::max(max_step, (sample.force_n - before.force_n).norm());
        produced_j += before.force_n.head<2>().dot((sample.position_m - before.position_m).head<2>());
        max_produced_j = std::max(max_produced_j, produced_j);
      }
    }
    // What the field can store and give back: a static field (band, repulsion) at most its peak force over
    // R_res per stroke entered; the timing target, which moves, at most its pull over the stroke's length.
    const ForceLawParameters& force = options.force;
    double store_j = 0.0;
    for (const PlacedStroke& stroke : scene.characters[0].strokes) {
      store_j += max_in_plane_n * (trial_case.mode == GuidanceMode::timing
                                       ? stroke.length_m() + force.constraint_radius_m
                                       : force.constraint_radius_m);
    }
    INFO(to_string(trial_case.mode) << ", U+" << std::hex << static_cast<unsigned>(trial_case.character)
                                    << std::dec << ", " << trial_case.rate_hz << " Hz: max step " << max_step
                                    << " N, peak " << max_force << " N, in-plane energy given at most "
                                    << max_produced_j << " J (field's store " << store_j << " J), net "
                                    << produced_j << " J");
    CHECK(finite);
    CHECK(trial.metrics.strokes_completed == trial.metrics.strokes_total);
    CHECK(max_step <= SafetyChainParameters{}.max_force_change_n_per_tick);
    CHECK(max_force <= peak_n);
    CHECK(max_produced_j <= store_j);
  }
}
