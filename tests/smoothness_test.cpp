// Smoothness of the rendered force (issue 5, paper section 6): full simulated trials on real
// characters with corners, hooks and crossing strokes, and the single smoothing stages.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "calligraphy/character_library.hpp"
#include "calligraphy/constraint_space.hpp"
#include "calligraphy/force_law.hpp"
#include "calligraphy/renderer.hpp"
#include "calligraphy/trial.hpp"

using namespace calligraphy;

namespace {

// 20 characters of the embedded set: turns (横折, 竖折), hooks (竖钩, 弯钩, 卧钩), crossings.
const std::u32string kCharacters = U"永我九乙也书之力母马弓心水长东为电风写凸";

Scene scene_of(char32_t c) { return Scene::lay_out({CharacterLibrary::embedded().load(c)}); }

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

StepFigures trial_steps(char32_t c, const TrialOptions& options) {
  const Scene scene = scene_of(c);
  const TrialResult result = run_simulated_trial(scene, options);
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

TrialOptions guided_novice(std::uint64_t seed) {
  TrialOptions options;
  options.seed = seed;
  options.force.guidance = true;
  options.writer = WriterProfile::novice();
  return options;
}

}  // namespace

TEST_CASE("Trials figures for docs/force-rendering.md", "[.smoothness-figures]") {
  std::printf("char  seed  max_step_N(chain)  max_step_N(no rate limit)  max_force_N  completed\n");
  for (const char32_t c : kCharacters) {
    for (const std::uint64_t seed : {1u, 2u}) {
      TrialOptions options = guided_novice(seed);
      if (std::getenv("F0")) options.force.friction_coefficient = 0.0;
      if (std::getenv("R0")) options.force.resistance_damping_n_s_per_m = 0.0;
      if (std::getenv("G0")) options.force.guidance = false;
      const StepFigures with = trial_steps(c, options);
      options.safety.max_force_change_n_per_tick = 0.0;
      const StepFigures without = trial_steps(c, options);
      std::printf("%s  %4llu  %17.4f  %25.4f  %11.3f  %s\n", utf8(c).c_str(),
                  static_cast<unsigned long long>(seed), with.max_step_n, without.max_step_n,
                  with.max_force_n, with.completed ? "yes" : "no");
    }
  }
}
