// Smoothness of the rendered force (Wang, Zhang & Yao 2006, section 6): full simulated trials on real
// characters with corners, hooks and crossing strokes, and the single smoothing stages.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy//model/character_library.hpp"
#include "calligraphy/collision/constraint_space.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"
#include "embedded_scenes.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;

namespace {

// 20 characters of the embedded set: turns (横折, 竖折), hooks (竖钩, 弯钩, 卧钩), crossings.
const std::u32string kCharacters = U"永我九乙也书之力母马弓心水长东为电风写凸";

std::string utf8(char32_t c) {
  std::string s;
  if (c < 0x800) {
    s += static_cast<char>(0xC0 | (c >> 6));
  } else {
    s += static_cast<char>(0xE0 | (c >> 12));
    s += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
  }
  s += static_cast<char>(0x80 | (c & 0x3F));
  return s;
}

struct StepFigures {
  double max_step_n = 0.0;
  double max_force_n = 0.0;
  bool all_finite = true;
  bool completed = false;
};

// A guided novice of seed `seed` writes `c` with `options`.
StepFigures trial_steps(char32_t c, const TrialOptions& options, std::uint64_t seed) {
  const Scene scene = calligraphy::testing::embedded_scene(c);
  SimulationOptions novice;
  novice.writer = WriterProfile::novice();
  novice.seed = seed;
  const TrialResult result = run_simulated_trial(scene, options, novice);
  StepFigures f;
  f.completed = result.metrics.completed_in_order;
  for (std::size_t k = 0; k < result.trace.size(); ++k) {
    const Vec3& force = result.trace[k].force_n;
    f.all_finite = f.all_finite && force.allFinite();
    f.max_force_n = std::max(f.max_force_n, force.norm());
    if (k > 0) f.max_step_n = std::max(f.max_step_n, (force - result.trace[k - 1].force_n).norm());
  }
  return f;
}

TrialOptions guided() {
  TrialOptions options;
  options.force.guidance = true;
  return options;
}

// The paper's force law without the section-6 smoothing.
ForceLawParameters unsmoothed() {
  ForceLawParameters p;
  p.constraint_taper_m = 0.0;
  p.crossfade_s = 0.0;
  p.paper_fade_s = 0.0;
  p.max_foot_speed_m_s = 1e6;
  p.friction_coefficient = 0.0;
  return p;
}

// One character: stroke 0 a 横折 (right, then down), data units.
Scene corner_scene() {
  Character c;
  c.code_point = U'口';
  Stroke hz;
  hz.typical_id = 7;
  hz.elements = {StrokeElement::line({200, 600}, {800, 600}), StrokeElement::line({800, 600}, {800, 100})};
  hz.attraction_factors = {1.0, 2.0, 2.0};
  c.strokes = {hz};
  return Scene::lay_out({c});
}

DeviceState at_data(const Scene& scene, const Vec2& data, double z) {
  DeviceState s;
  const Vec2 p = scene.characters[0].placement.to_paper(data);
  s.position_m = Vec3(p.x(), p.y(), z);
  return s;
}

RendererOptions without_rate_limit() {
  RendererOptions o;
  o.safety.max_force_change_n_per_tick = 0.0;
  o.safety.start_ramp_n_per_s = 0.0;
  return o;
}

// Largest per-tick force change while the tip moves 2 mm outside the 横折's corner: along the first
// element past x = 800 (the plane pops, X_S jumps to the vertical element), then down.
double corner_max_step(const ForceLawParameters& force) {
  const Scene scene = corner_scene();
  Renderer r(scene, force, simulated_phantom_desktop_info(), without_rate_limit());
  const double z = scene.layout.paper_z_m - 0.0005;
  r.tick(at_data(scene, {205, 600}, z));  // WS at the start
  Vec3 previous = Vec3::Zero();
  double max_step = 0.0;
  const int n = 2000;
  for (int k = 0; k <= n; ++k) {  // 0.5 data units per tick: ~30 mm/s
    const double u = 250.0 + 0.5 * k;
    const Vec2 data = u < 830.0 ? Vec2(u, 630.0) : Vec2(830.0, 630.0 - (u - 830.0));
    const RenderOutput out = r.tick(at_data(scene, data, z));
    if (k > 0) max_step = std::max(max_step, (out.force_n - previous).norm());
    previous = out.force_n;
  }
  return max_step;
}

}  // namespace

// 20 characters x 2 seeds in Release; under the sanitizers 6 of those 40 trials drawn at random
// (tests/test_sizing.hpp).
constexpr std::size_t kSanitizedSmoothnessTrials = 6;

TEST_CASE("Through full guided trials on 20 characters the per-tick force change stays within the limit",
          "[smoothness][safety]") {
  std::vector<std::pair<char32_t, std::uint64_t>> trials;
  for (const char32_t c : kCharacters) {
    for (const std::uint64_t seed : {1u, 2u}) trials.emplace_back(c, seed);
  }
  for (const auto& [c, seed] :
       calligraphy::testing::sanitizer_subset(trials, kSanitizedSmoothnessTrials, "character x seed")) {
    TrialOptions options = guided();
    options.keep_trace = true;
    const StepFigures chain = trial_steps(c, options, seed);
    options.safety.max_force_change_n_per_tick = 0.0;  // the smoothing alone, without the rate limit
    const StepFigures smoothing = trial_steps(c, options, seed);
    INFO(utf8(c) << " seed " << seed << ": max per-tick change " << chain.max_step_n << " N with the chain, "
                 << smoothing.max_step_n << " N without its rate limit");
    CHECK(chain.completed);
    CHECK(chain.all_finite);
    CHECK(smoothing.all_finite);
    CHECK(chain.max_step_n <= SafetyChainParameters{}.max_force_change_n_per_tick + 1e-9);
    CHECK(smoothing.max_step_n <= SafetyChainParameters{}.max_force_change_n_per_tick);
  }
}

TEST_CASE("Without the smoothing and the rate limit the paper's force law steps (the trial test can fail)",
          "[smoothness]") {
  TrialOptions options = guided();
  options.force = unsmoothed();
  options.safety.max_force_change_n_per_tick = 0.0;
  options.safety.start_ramp_n_per_s = 0.0;
  const StepFigures raw = trial_steps(U'我', options, 1);
  INFO("max per-tick change " << raw.max_step_n << " N");
  // Above the limit, so the trial test above fails on this force law.
  CHECK(raw.max_step_n > SafetyChainParameters{}.max_force_change_n_per_tick);
}

TEST_CASE("F_et tapers to zero at the constraint-space edge", "[smoothness]") {
  const double r = 0.006;
  const double band = 0.002;
  CHECK(constraint_taper(0.0, r, band) == 1.0);
  CHECK(constraint_taper(r - band, r, band) == 1.0);
  CHECK(constraint_taper(r, r, band) == 0.0);
  CHECK(constraint_taper(r - 1e-9, r, band) < 1e-8);
  CHECK(constraint_taper(r - band / 2, r, band) == Approx(0.5));
  double last = 1.0;
  for (double d = r - band; d <= r; d += band / 100) {
    const double w = constraint_taper(d, r, band);
    REQUIRE(w <= last);
    last = w;
  }
  CHECK(constraint_taper(r - 1e-9, r, 0.0) == 1.0);  // band 0: the paper's step
  // In the renderer: just inside R_res the guidance force is near zero instead of K a R.
  const Scene scene = corner_scene();
  ForceLawParameters p = unsmoothed();
  p.constraint_taper_m = band;
  p.resistance_damping_n_s_per_m = 0.0;
  Renderer renderer(scene, p, simulated_phantom_desktop_info(), without_rate_limit());
  const double z = scene.layout.paper_z_m;
  renderer.tick(at_data(scene, {205, 600}, z));
  const double units_per_m = 1024.0 / 0.06;
  const auto out = renderer.tick(at_data(scene, {500, 600 + (r - 1e-5) * units_per_m}, z));
  REQUIRE(out.in_constraint_space);
  CHECK(out.force_n.head<2>().norm() < 0.01);  // the untapered law gives 400 * 1.5 * 6 mm = 3.6 N
}

TEST_CASE("The cross-fade and the foot-speed limit spread the force step at a corner", "[smoothness]") {
  const double raw = corner_max_step(unsmoothed());
  const double smooth = corner_max_step(ForceLawParameters{});
  INFO("max per-tick change at the corner: " << raw << " N unsmoothed, " << smooth << " N smoothed");
  CHECK(raw > 0.5);
  CHECK(smooth < 0.1);
}

TEST_CASE("The paper force fades in when CS is entered from AS below the paper", "[smoothness]") {
  const Scene scene = corner_scene();
  ForceLawParameters p;
  p.friction_coefficient = 0.0;
  Renderer r(scene, p, simulated_phantom_desktop_info(), without_rate_limit());
  const double z = scene.layout.paper_z_m - 0.004;  // 4 mm deep: 3.2 N at full weight
  const Vec2 outside = scene.characters[0].bounding_box.max() + Vec2(0.01, 0.01);
  DeviceState s;
  s.position_m = Vec3(outside.x(), outside.y(), scene.layout.paper_z_m + 0.001);
  r.tick(s);
  s.position_m.z() = z;
  CHECK(r.tick(s).state == InteractionState::adjusting);
  DeviceState inside = at_data(scene, {500, 300}, z);
  double previous = 0.0;
  const double per_tick = 3.2 / (p.paper_fade_s * 1000.0);
  for (int k = 0; k < 300; ++k) {
    const RenderOutput out = r.tick(inside);
    REQUIRE(out.state == InteractionState::calibration);
    REQUIRE(out.force_n.z() - previous <= per_tick + 1e-9);
    previous = out.force_n.z();
  }
  CHECK(previous == Approx(3.2));
}

TEST_CASE("Paper damping acts on inward motion only", "[smoothness]") {
  const Scene scene = corner_scene();
  ForceLawParameters p = unsmoothed();
  p.paper_damping_n_s_per_m = 0.4;
  Renderer r(scene, p, simulated_phantom_desktop_info(), without_rate_limit());
  DeviceState s = at_data(scene, {500, 300}, scene.layout.paper_z_m - 0.001);
  s.velocity_m_s.z() = -0.05;
  CHECK(r.tick(s).force_n.z() == Approx(0.8 + 0.4 * 0.05));
  s.velocity_m_s.z() = 0.05;
  CHECK(r.tick(s).force_n.z() == Approx(0.8));
}

TEST_CASE("Paper friction: Coulomb outside the stick band, viscous inside it", "[smoothness]") {
  const double mu = 0.2;
  const double band = 0.01;
  CHECK(friction_force(Vec2(0.05, 0.0), 2.0, mu, band).isApprox(Vec2(-0.4, 0.0)));
  CHECK(friction_force(Vec2(0.0, -0.3), 2.0, mu, band).isApprox(Vec2(0.0, 0.4)));
  CHECK(friction_force(Vec2(0.005, 0.0), 2.0, mu, band).isApprox(Vec2(-0.2, 0.0)));
  CHECK(friction_force(Vec2::Zero(), 2.0, mu, band).isZero());
  CHECK(friction_force(Vec2(0.05, 0.0), 0.0, mu, band).isZero());
  // Continuous across the band's edge.
  CHECK((friction_force(Vec2(band * (1 - 1e-9), 0.0), 2.0, mu, band) -
         friction_force(Vec2(band * (1 + 1e-9), 0.0), 2.0, mu, band))
            .norm() < 1e-8);
  // Always against the motion.
  for (double a = 0.0; a < 6.3; a += 0.1) {
    const Vec2 v = 0.02 * Vec2(std::cos(a), std::sin(a));
    REQUIRE(friction_force(v, 1.0, mu, band).dot(v) < 0.0);
  }
}

TEST_CASE("Feature planes have a hysteresis band", "[smoothness]") {
  const StrokeElement lse = StrokeElement::line({0.0, 0.0}, {0.01, 0.0});
  CHECK(feature_plane_passed(lse, Vec2(0.0101, 0.0)));
  CHECK_FALSE(feature_plane_passed(lse, Vec2(0.0101, 0.0), 0.0002));
  CHECK(feature_plane_passed(lse, Vec2(0.0103, 0.0), 0.0002));
}

TEST_CASE("Trials figures for docs/force-rendering.md", "[.smoothness-figures]") {
  std::printf("char  seed  max_step_N(chain)  max_step_N(no rate limit)  max_force_N  completed\n");
  for (const char32_t c : kCharacters) {
    for (const std::uint64_t seed : {1u, 2u}) {
      TrialOptions options = guided();
      const StepFigures with = trial_steps(c, options, seed);
      options.safety.max_force_change_n_per_tick = 0.0;
      const StepFigures without = trial_steps(c, options, seed);
      std::printf("%s  %4llu  %17.4f  %25.4f  %11.3f  %s\n", utf8(c).c_str(),
                  static_cast<unsigned long long>(seed), with.max_step_n, without.max_step_n,
                  with.max_force_n, with.completed ? "yes" : "no");
    }
  }
}
