// The README's usage example: model a character, lay it out on the paper, run a guided trial on the
// simulated device, and print the metrics.
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/sim/simulated_hand.hpp>
#include <calligraphy/trial/trial.hpp>
#include <cmath>
#include <cstdio>

int main() {
  using namespace calligraphy;
  const Character yong = CharacterLibrary::embedded().load(U'永');  // hanzi-writer-data medians, fitted
  const Scene scene = Scene::lay_out({yong});                       // 60 mm box on the paper z = 0

  TrialOptions options;                              // 1 kHz, simulated Phantom Desktop, novice writer
  options.force.guidance_stiffness_n_per_m = 400.0;  // K_et [N/m], eq. (8)
  SimulationOptions simulation;                      // the simulated writer and device (calligraphy/sim)
  simulation.seed = 1;
  const TrialResult result = run_simulated_trial(scene, options, simulation);

  const TrialMetrics& m = result.metrics;
  std::printf("%zu/%zu strokes, mean deviation %.2f mm, max |F| %.2f N\n", m.strokes_completed,
              m.strokes_total, m.mean_deviation_m.value_or(std::nan("")) * 1e3, m.max_force_n);
  return m.completed_in_order ? 0 : 1;
}
