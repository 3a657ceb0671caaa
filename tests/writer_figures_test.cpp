// Figures of the simulated writer on the tuning half of the embedded set (docs/writer.md): guidance on
// and off for the same seeded writers. Hidden: run with "[.writer-figures]".
#include <catch2/catch.hpp>
#include <cstdio>

#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

struct Figures {
  double deviation_mm = 0.0;
  double time_s = 0.0;
  std::size_t order_errors = 0;
  std::size_t backwards = 0;
  bool in_order = false;
  std::size_t refusals = 0;
  std::size_t attempts = 0;
};

Figures figures(const Scene& scene, const WriterTrialOptions& options) {
  const WriterTrial trial = run_writer_trial(scene, options);
  const std::vector<PenSample> pen = pen_samples(scene, trial.trace);
  const CharacterScore score = score_trace(scene.characters[0], pen);
  Figures f;
  f.deviation_mm = score.totals.deviation ? score.totals.deviation->mean_m * 1e3 : -1.0;
  f.time_s = score.totals.total_time_s.value_or(0.0);
  f.order_errors = score.order_errors;
  f.backwards = score.backwards_strokes;
  f.in_order = trial.metrics.completed_in_order;
  f.refusals = trial.log.refusals;
  f.attempts = trial.log.attempts.size();
  return f;
}

}  // namespace

TEST_CASE("Writer figures on the tuning half of the embedded set", "[.writer-figures]") {
  for (const char* profile_name : {"novice", "foreign"}) {
    std::printf(
        "profile char seed  dev_off dev_on  time_off time_on  order_off back_off order_on back_on  "
        "inorder_on refusals_on attempts_on\n");
    for (const char32_t c : embedded_half(false)) {
      const Scene scene = scene_of(c);
      for (const std::uint64_t seed : {1u}) {
        WriterTrialOptions on;
        on.writer = writer_profile(profile_name);
        on.seed = seed;
        WriterTrialOptions off = on;
        off.force.guidance = false;
        const Figures a = figures(scene, off);
        const Figures b = figures(scene, on);
        std::printf("%s U+%04X %llu  %.3f %.3f  %.2f %.2f  %zu %zu %zu %zu  %d %zu %zu\n", profile_name,
                    static_cast<unsigned>(c), static_cast<unsigned long long>(seed), a.deviation_mm,
                    b.deviation_mm, a.time_s, b.time_s, a.order_errors, a.backwards, b.order_errors,
                    b.backwards, b.in_order ? 1 : 0, b.refusals, b.attempts);
      }
    }
  }
}
