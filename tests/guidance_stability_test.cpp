// Every guidance mode keeps the renderer's stability guarantees (docs/force-rendering.md): through full
// guided trials at 1, 4 and 10 kHz the per-tick force change stays within the safety chain's limit
// without its rate limiter (the taper, cross-fade and foot-speed limit do the smoothing), and a pen
// held in WS under each mode's spring, at half and 0.9 of Colgate's bound 2 b / T, takes no growing
// energy from the device over 60 s (bounded, for every mode whose target does not move along the stroke).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "calligraphy/render/passivity.hpp"
#include "hand_models.hpp"
#include "test_sizing.hpp"
#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

const char* name(GuidanceMode mode) { return to_string(mode); }

// A teacher for the replay mode: the skilled writer's trial of the same scene.
std::vector<TeacherSample> teacher_of(const Scene& scene, double rate_hz) {
  WriterTrialOptions teacher;
  teacher.writer = WriterProfile::skilled();
  teacher.seed = 21;
  teacher.rate_hz = rate_hz;
  const WriterTrial recorded = run_writer_trial(scene, teacher);
  REQUIRE(recorded.metrics.completed_in_order);
  std::vector<TeacherSample> samples;
  for (const TrialSample& s : recorded.trace) samples.push_back(TeacherSample{s.time_s, s.position_m});
  return samples;
}

ForceLawParameters mode_parameters(GuidanceMode mode, const Scene& scene, double rate_hz) {
  ForceLawParameters force;
  force.guidance_law = default_guidance_law(mode);
  if (mode == GuidanceMode::fading) std::get<FadingGuidance>(force.guidance_law).gain = 0.5;
  if (mode == GuidanceMode::replay)
    std::get<ReplayGuidance>(force.guidance_law).teacher_trajectory = teacher_of(scene, rate_hz);
  return force;
}

// A synthetic teacher for 口: each stroke written along its elements at 20 mm/s; on the first
// stroke the pen stops `hold_after_m` from the start for `hold_s`.
std::vector<TeacherSample> teacher_holding(const Scene& scene, double hold_after_m, double hold_s) {
  const double paper_z = scene.layout.paper_z_m;
  const double down = paper_z - 0.0005;
  const double up = paper_z + 0.005;
  std::vector<TeacherSample> samples;
  double t = 0.0;
  bool held = false;
  for (const PlacedStroke& s : scene.characters[0].strokes) {
    samples.push_back({t += 0.5, Vec3(s.start().x(), s.start().y(), up)});
    samples.push_back({t += 0.2, Vec3(s.start().x(), s.start().y(), down)});
    double travelled_m = 0.0;
    Vec2 last = s.start();
    for (std::size_t j = 0; j < s.elements.size(); ++j) {
      const StrokeElement& e = s.elements[j];
      if (j > 0) {  // 1 mm past the feature point, as writers follow through, and back
        const Vec2 past = e.start() + 0.001 * s.elements[j - 1].unit_tangent(1.0);
        samples.push_back({t += 0.05, Vec3(past.x(), past.y(), down)});
        samples.push_back({t += 0.05, Vec3(e.start().x(), e.start().y(), down)});
      }
      for (int i = 1; i <= 100; ++i) {
        const Vec2 p = e.point(static_cast<double>(i) / 100.0);
        travelled_m += (p - last).norm();
        t += (p - last).norm() / 0.02;
        last = p;
        samples.push_back({t, Vec3(p.x(), p.y(), down)});
        if (!held && travelled_m >= hold_after_m) {
          held = true;
          samples.push_back({t += hold_s, Vec3(p.x(), p.y(), down)});
        }
      }
    }
    const Vec2 beyond = s.end() + 0.002 * s.elements.back().unit_tangent(1.0);
    samples.push_back({t += 0.1, Vec3(beyond.x(), beyond.y(), down)});
    samples.push_back({t += 0.2, Vec3(beyond.x(), beyond.y(), up)});
  }
  return samples;
}

// A pen held in WS: the stylus starts 1 mm above 口's first stroke, 3 mm along it and 2 mm to its side,
// and the hand presses towards that point 2 mm below the paper; guidance pulls it onto the stroke.
struct HoldRun {
  double max_energy_j = 0.0;
  double max_energy_first_j = 0.0;
  double max_energy_last_j = 0.0;
  bool stayed_writing = true;
  double max_force_n = 0.0;
};

enum class Hand { relaxed, stiff, none };

HoldRun hold_in_writing(GuidanceMode mode, Hand hand, double rate_hz, double stiffness_n_per_m,
                        double seconds) {
  static const Scene scene = scene_of(U'口');
  const PlacedStroke& stroke = scene.characters[0].strokes[0];
  const Vec2 along = stroke.elements[0].unit_tangent(0.0);
  const Vec2 side(-along.y(), along.x());
  const Vec2 start = stroke.start() + 0.003 * along + 0.002 * side;  // inside the start neighbourhood
  const double paper_z = scene.layout.paper_z_m;
  SimulatedDeviceParameters device_parameters;
  device_parameters.initial_position_m = Vec3(start.x(), start.y(), paper_z + 0.001);
  SimulatedDevice device(device_parameters);
  const Vec3 press(start.x(), start.y(), paper_z - 0.002);
  ImpedanceHand relaxed = relaxed_hand(press);
  ImpedanceHand stiff = stiff_hand(press);
  NoHand weight(0.5);
  device.attach_hand(hand == Hand::relaxed ? static_cast<HandModel*>(&relaxed)
                     : hand == Hand::stiff ? static_cast<HandModel*>(&stiff)
                                           : static_cast<HandModel*>(&weight));
  device.open();
  ForceLawParameters force;
  force.guidance_law = default_guidance_law(mode);
  force.guidance_stiffness_n_per_m = stiffness_n_per_m;
  if (mode == GuidanceMode::fading) {
    std::get<FadingGuidance>(force.guidance_law).gain = 0.5;
    force.guidance_stiffness_n_per_m = 2.0 * stiffness_n_per_m;  // the effective stiffness g K is the same
  }
  if (mode == GuidanceMode::replay) {
    // The teacher touches down at the start of the first stroke, moves 5 mm along it and stays there
    // past the test's end (a fixed attraction point that is not the foot point), then writes the
    // rest of that stroke and the others, so that the recording is complete.
    std::get<ReplayGuidance>(force.guidance_law).teacher_trajectory =
        teacher_holding(scene, 0.005, seconds + 100.0);
  }
  RendererOptions options;
  options.rate_hz = rate_hz;
  Renderer renderer(scene, force, device.info(), options);
  HoldRun run;
  double energy = 0.0;
  bool writing = false;
  const double dt = 1.0 / rate_hz;
  const auto ticks = static_cast<long>(std::lround(seconds * rate_hz));
  const double window = seconds / 6.0;
  for (long k = 0; k < ticks; ++k) {
    DeviceState state;
    if (device.read_state(state) != DeviceFault::none) FAIL("the simulated device faulted");
    const RenderOutput out = renderer.tick(state);
    if (device.write_force(out.force_n) != DeviceFault::none) FAIL("the simulated device faulted");
    const Vec3 before = device.true_position();
    const Vec3 applied = device.applied_force();
    device.advance(dt);
    energy += applied.dot(device.true_position() - before);
    const double t = static_cast<double>(k + 1) * dt;
    run.max_energy_j = std::max(run.max_energy_j, energy);
    if (t <= window) run.max_energy_first_j = std::max(run.max_energy_first_j, energy);
    if (t >= seconds - window) run.max_energy_last_j = std::max(run.max_energy_last_j, energy);
    run.max_force_n = std::max(run.max_force_n, out.force_n.norm());
    // After the touch-down has settled (a pen dropped onto the paper without a hand bounces off it).
    if (t > 1.0 && out.state == InteractionState::writing) writing = true;
    if (writing && out.state != InteractionState::writing) run.stayed_writing = false;
  }
  if (!writing) run.stayed_writing = false;
  return run;
}

#if defined(CALLIGRAPHY_TEST_SANITIZED)
constexpr double kHoldSeconds = 20.0;
#else
constexpr double kHoldSeconds = 60.0;
#endif
const std::u32string kTrialCharacters = U"永我乙";
// Guided trials per sanitizer run, drawn from the 27 of rate x character x mode (tests/test_sizing.hpp).
constexpr std::size_t kSanitizedTrials = 3;
// Held pens per sanitizer run, drawn from the 72 of rate x mode x hand x stiffness.
constexpr std::size_t kSanitizedHolds = 6;
constexpr double kGrowthTolerance_j = 5e-4;  // as tests/passivity_test.cpp
constexpr double kBoundedEnergy_j = 0.01;
constexpr double kDeviceDamping = 0.5;  // SimulatedDeviceParameters' default b [N s/m]

}  // namespace

TEST_CASE("Every guidance mode keeps the per-tick force change within the limit at 1, 4 and 10 kHz",
          "[guidance][smoothness]") {
  struct Case {
    double rate_hz;
    char32_t character;
    GuidanceMode mode;
  };
  std::vector<Case> cases;
  for (const double rate : {1000.0, 4000.0, 10000.0}) {
    for (const char32_t c : kTrialCharacters) {
      for (const GuidanceMode mode : {GuidanceMode::fixed, GuidanceMode::fading, GuidanceMode::replay})
        cases.push_back({rate, c, mode});
    }
  }
  for (const Case& trial_case :
       sanitizer_subset(cases, kSanitizedTrials, "rate x character x guidance mode")) {
    const Scene scene = scene_of(trial_case.character);
    WriterTrialOptions options;
    options.seed = 1;
    options.rate_hz = trial_case.rate_hz;
    options.force = mode_parameters(trial_case.mode, scene, trial_case.rate_hz);
    options.safety.max_force_change_n_per_tick = 0.0;  // the smoothing alone
    const WriterTrial trial = run_writer_trial(scene, options);
    double max_step = 0.0;
    bool finite = true;
    for (std::size_t k = 0; k < trial.trace.size(); ++k) {
      finite = finite && trial.trace[k].force_n.allFinite();
      if (k > 0) max_step = std::max(max_step, (trial.trace[k].force_n - trial.trace[k - 1].force_n).norm());
    }
    INFO(name(trial_case.mode) << " mode, " << trial_case.rate_hz << " Hz, U+" << std::hex
                               << static_cast<unsigned>(trial_case.character) << std::dec
                               << ": max per-tick change " << max_step << " N");
    CHECK(trial.metrics.completed_in_order);
    CHECK(finite);
    CHECK(max_step <= SafetyChainParameters{}.max_force_change_n_per_tick);
  }
}

TEST_CASE("Up to Colgate's bound a pen held in WS takes no growing energy in any guidance mode",
          "[guidance][passivity]") {
  // Only held pens: without a hand (a 0.5 N weight, no grip) the pen does not stay in WS in any mode, the
  // fixed one included: the fixture swings it across the stroke and it bounces off the paper
  // (docs/force-rendering.md). The paper contact without a hand is tests/passivity_test.cpp's.
  struct Case {
    double rate_hz;
    GuidanceMode mode;
    Hand hand;
    double share;  // of Colgate's bound
  };
  std::vector<Case> cases;
  for (const double rate : {1000.0, 4000.0, 10000.0}) {
    for (const GuidanceMode mode : guidance_modes()) {
      for (const Hand hand : {Hand::relaxed, Hand::stiff}) {
        for (const double share : {0.5, 0.9}) cases.push_back({rate, mode, hand, share});
      }
    }
  }
  for (const Case& hold : sanitizer_subset(cases, kSanitizedHolds, "rate x mode x hand x stiffness")) {
    const double stiffness = hold.share * colgate_stiffness_bound(kDeviceDamping, hold.rate_hz);
    const HoldRun run = hold_in_writing(hold.mode, hold.hand, hold.rate_hz, stiffness, kHoldSeconds);
    INFO(name(hold.mode) << " mode, hand " << static_cast<int>(hold.hand) << ", " << hold.rate_hz
                         << " Hz, g K = " << stiffness << " N/m: energy max " << run.max_energy_j
                         << " J, first 10 s " << run.max_energy_first_j << " J, last 10 s "
                         << run.max_energy_last_j << " J, max force " << run.max_force_n << " N");
    CHECK(run.stayed_writing);
    CHECK(run.max_energy_last_j <= std::max(run.max_energy_first_j, 0.0) + kGrowthTolerance_j);
    if (hold.mode == GuidanceMode::timing) {
      // The timing target is not a fixed point: it moves along the stroke and drags the held pen after it,
      // so it may do work, but never more than its saturated pull (or the device's peak) over the stroke.
      static const Scene scene = scene_of(U'口');
      const double pull_n = std::min(stiffness * kDefaultMaxLeadM, run.max_force_n);
      CHECK(run.max_energy_j <= pull_n * scene.characters[0].strokes[0].length_m());
    } else {
      CHECK(run.max_energy_j <= kBoundedEnergy_j);
    }
  }
}
