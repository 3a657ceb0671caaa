// The simulated writer's error modes and how guidance answers them (docs/writer.md): strokes out of
// order and backwards stay in the trace without guidance and are refused under it, after which the
// writer follows the display's hint; lifts in the middle of a stroke, touches outside the box and
// hesitations. Characters from the tuning half of the embedded set.
#include <catch2/catch.hpp>
#include <string>

#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

WriterProfile careful_novice() {
  WriterProfile p = WriterProfile::novice();
  p.mid_stroke_lift_probability = 0.0;
  p.outside_touch_probability = 0.0;
  p.hesitation_probability = 0.0;
  return p;
}

CharacterScore score(const Scene& scene, const WriterTrial& trial) {
  return score_trace(scene.characters[0], pen_samples(scene, trial.trace));
}

}  // namespace

TEST_CASE("Strokes out of order stay out of order without guidance and are refused under it", "[writer]") {
  const Scene scene = scene_of(U'四');  // 5 strokes
  WriterTrialOptions off;
  off.writer = careful_novice();
  off.writer.order_error_probability = 1.0;  // swaps strokes 0-1 and 2-3
  off.seed = 2;
  off.force.guidance = false;
  WriterTrialOptions on = off;
  on.force.guidance = true;

  const WriterTrial unguided = run_writer_trial(scene, off);
  REQUIRE(unguided.plan.size() == 5);
  CHECK(unguided.plan[0].stroke == 1);
  CHECK(unguided.plan[1].stroke == 0);
  CHECK(unguided.log.refusals == 0);
  CHECK(unguided.log.out_of_order_attempts() >= 2);
  CHECK(score(scene, unguided).order_errors >= 2);
  CHECK_FALSE(unguided.metrics.completed_in_order);

  const WriterTrial guided = run_writer_trial(scene, on);
  CHECK(guided.metrics.completed_in_order);
  CHECK(guided.log.refusals >= 1);
  bool refused_before = false;
  for (const WriterAttempt& a : guided.log.attempts) {
    INFO("attempt at stroke " << a.stroke << " from " << a.start_s << " s");
    if (a.out_of_order) CHECK(a.end == AttemptEnd::refused);
    // Once refused, the writer has learnt that the display leads, and writes the hinted strokes.
    if (refused_before) CHECK(a.follows_hint);
    refused_before = refused_before || a.end == AttemptEnd::refused;
  }
  // What the writer wrote to the end, it wrote in the reference order.
  const std::vector<std::size_t> written = guided.log.completed_order();
  CHECK(std::is_sorted(written.begin(), written.end()));
  CHECK(score(scene, guided).order_errors == 0);
}

TEST_CASE("Strokes written backwards stay backwards without guidance and are refused under it", "[writer]") {
  const Scene scene = scene_of(U'口');
  WriterTrialOptions off;
  off.writer = careful_novice();
  off.writer.backwards_probability = 1.0;
  off.seed = 6;
  off.force.guidance = false;
  WriterTrialOptions on = off;
  on.force.guidance = true;

  // Without guidance nothing resists a stroke written backwards: each is written whole, the display does
  // not take it, and the writer, seeing that, writes it again as the display shows it.
  const WriterTrial unguided = run_writer_trial(scene, off);
  CHECK(unguided.log.backwards_attempts() == 3);
  CHECK(unguided.log.refusals == 0);
  for (const WriterAttempt& a : unguided.log.attempts) {
    if (a.reversed) CHECK(a.end == AttemptEnd::not_accepted);
  }
  CHECK(unguided.log.not_accepted == 3);
  CHECK(unguided.metrics.completed_in_order);

  const WriterTrial guided = run_writer_trial(scene, on);
  CHECK(guided.metrics.completed_in_order);
  CHECK(guided.log.refused_backwards() == guided.log.backwards_attempts());
  for (const WriterAttempt& a : guided.log.attempts) {
    if (a.end == AttemptEnd::completed) CHECK_FALSE(a.reversed);
  }
  CHECK(score(scene, guided).backwards_strokes == 0);
}

TEST_CASE("A stroke cleared after a lift in its middle is written again, with or without guidance",
          "[writer]") {
  // 人: every element is 20 mm or longer, so a lift at 30-70 % of one is outside the start neighbourhood
  // and more than the allowed shortfall from the end. (On 十, whose strokes begin with a 4 mm entry
  // element, the pen touching down again inside the start neighbourhood starts a new attempt that writes
  // the whole stroke, as it should.)
  const Scene scene = scene_of(U'人');
  for (const bool guidance : {false, true}) {
    WriterTrialOptions options;
    options.writer = careful_novice();
    options.writer.mid_stroke_lift_probability = 1.0;
    options.writer.correction_per_attempt = 1.0;  // the second attempt is careful: no lift
    options.force.guidance = guidance;
    options.seed = 8;
    const WriterTrial trial = run_writer_trial(scene, options);
    INFO("guidance " << guidance);
    CHECK(trial.log.mid_stroke_lifts() >= 2);
    std::size_t interrupted_or_refused = 0;
    for (const WriterAttempt& a : trial.log.attempts) {
      if (a.mid_stroke_lift) CHECK(a.end != AttemptEnd::completed);
      if (a.end == AttemptEnd::interrupted || a.end == AttemptEnd::refused) ++interrupted_or_refused;
    }
    CHECK(interrupted_or_refused == trial.log.mid_stroke_lifts());
    bool abandoned = false;  // the renderer saw the pen lifted in WS
    for (std::size_t k = 1; k < trial.trace.size(); ++k) {
      abandoned = abandoned || (trial.trace[k - 1].state == InteractionState::writing &&
                                trial.trace[k].state == InteractionState::separation &&
                                trial.trace[k].stroke == trial.trace[k - 1].stroke);
    }
    CHECK(abandoned);
    CHECK(trial.metrics.completed_in_order);
  }
}

TEST_CASE("Touches outside the box are AS and change nothing else and hesitations take time", "[writer]") {
  const Scene scene = scene_of(U'口');
  WriterTrialOptions plain;
  plain.writer = careful_novice();
  plain.seed = 12;
  WriterTrialOptions touching = plain;
  touching.writer.outside_touch_probability = 1.0;
  WriterTrialOptions hesitant = plain;
  hesitant.writer.hesitation_probability = 1.0;

  const WriterTrial base = run_writer_trial(scene, plain);
  const WriterTrial outside = run_writer_trial(scene, touching);
  const WriterTrial slow = run_writer_trial(scene, hesitant);
  CHECK(outside.log.outside_touches() == outside.log.attempts.size());
  std::size_t adjusting = 0;
  for (const TrialSample& s : outside.trace) {
    if (s.state == InteractionState::adjusting) ++adjusting;
  }
  CHECK(adjusting > 0);
  CHECK(outside.metrics.completed_in_order);
  CHECK(slow.log.hesitations() == slow.log.attempts.size());
  CHECK(slow.metrics.completed_in_order);
  CHECK(slow.metrics.time_s > base.metrics.time_s + 0.5 * 3 * hesitant.writer.hesitation_s);
}
