#include "calligraphy/trial/trial.hpp"

#include <catch2/catch.hpp>

#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "embedded_scenes.hpp"

using namespace calligraphy;

namespace {}  // namespace

TEST_CASE("A guided trial on 永 completes every stroke in order", "[trial]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"永");
  TrialOptions options;
  const TrialResult result = run_simulated_trial(scene, options);
  CHECK(result.metrics.strokes_total == 5);
  CHECK(result.metrics.strokes_completed == 5);
  CHECK(result.metrics.completed_in_order);
  CHECK(result.metrics.max_force_n <= simulated_phantom_desktop_info().max_force_n);
  for (const auto& s : result.trace) REQUIRE(s.force_n.allFinite());
}

TEST_CASE("For the same seeded novice, guidance lowers the mean deviation", "[trial]") {
  for (const char32_t c : std::u32string(U"永我九")) {
    const Scene scene = calligraphy::testing::scene_of_text(std::u32string(1, c));
    for (std::uint64_t seed : {0u, 7u}) {
      TrialOptions on;
      on.keep_trace = false;
      TrialOptions off = on;
      off.force.guidance = false;
      SimulationOptions simulation;
      simulation.seed = seed;
      const auto with = run_simulated_trial(scene, on, simulation).metrics;
      const auto without = run_simulated_trial(scene, off, simulation).metrics;
      INFO("character U+" << std::hex << static_cast<unsigned>(c) << " seed " << seed);
      REQUIRE(with.strokes_completed == with.strokes_total);
      CHECK(with.mean_deviation_m < without.mean_deviation_m);
    }
  }
}

TEST_CASE("Trials are deterministic for a seed and differ across seeds", "[trial]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"口");
  const TrialOptions a;
  SimulationOptions simulation;
  simulation.seed = 3;
  const auto first = run_simulated_trial(scene, a, simulation).metrics;
  const auto again = run_simulated_trial(scene, a, simulation).metrics;
  CHECK(first.mean_deviation_m == again.mean_deviation_m);
  CHECK(first.time_s == again.time_s);
  simulation.seed = 4;
  CHECK(run_simulated_trial(scene, a, simulation).metrics.mean_deviation_m != first.mean_deviation_m);
}

TEST_CASE("A character group is written one character after another", "[trial]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"口九");
  REQUIRE(scene.characters.size() == 2);
  CHECK(scene.characters[0].bounding_box.max().x() < scene.characters[1].bounding_box.min().x());
  const auto result = run_simulated_trial(scene, TrialOptions{});
  CHECK(result.metrics.strokes_completed == 5);
  // The strokes of the second character come after all of the first.
  double first_done = 0.0;
  double second_started = 1e9;
  for (const auto& s : result.trace) {
    if (s.stroke == 2 && s.state == InteractionState::writing) first_done = std::max(first_done, s.time_s);
    if (s.stroke == 3 && s.state == InteractionState::writing)
      second_started = std::min(second_started, s.time_s);
  }
  CHECK(first_done < second_started);
}
