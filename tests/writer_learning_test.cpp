// Learning across repetitions (writer_learning.hpp): the exponential practice law moves bias and error
// rates towards the skilled writer's, by the feedback each repetition gave.
#include "calligraphy/sim/writer_learning.hpp"

#include <catch2/catch.hpp>
#include <cmath>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

TEST_CASE("Without a learning rate the profile does not change", "[writer]") {
  const WriterProfile foreign = WriterProfile::foreign();
  RepetitionOutcome outcome;
  outcome.guidance_share = 1.0;
  const WriterProfile next = next_repetition_profile(foreign, outcome);
  CHECK(next.bias_offset_m == foreign.bias_offset_m);
  CHECK(next.order_error_probability == foreign.order_error_probability);
}

TEST_CASE("Bias shrinks towards the skilled writer's, faster with guidance", "[writer]") {
  WriterProfile learner = WriterProfile::foreign();
  learner.learning_rate = 0.3;
  const WriterProfile skilled = WriterProfile::skilled();
  RepetitionOutcome guided;
  guided.guidance_share = 1.0;
  RepetitionOutcome unguided;
  const WriterProfile a = next_repetition_profile(learner, guided);
  const WriterProfile b = next_repetition_profile(learner, unguided);
  CHECK(a.bias_offset_m < b.bias_offset_m);
  CHECK(b.bias_offset_m < learner.bias_offset_m);
  // One step of q* + (q - q*) exp(-lambda w), w = 1 with guidance.
  CHECK(a.bias_offset_m ==
        Approx(skilled.bias_offset_m + (learner.bias_offset_m - skilled.bias_offset_m) * std::exp(-0.3)));
  // Many repetitions approach the asymptote and never pass it.
  WriterProfile p = learner;
  for (int n = 0; n < 100; ++n) p = next_repetition_profile(p, guided);
  CHECK(p.bias_offset_m == Approx(skilled.bias_offset_m).margin(1e-9));
  CHECK(p.bias_offset_m >= skilled.bias_offset_m);
  CHECK(p.scale_error == Approx(skilled.scale_error).margin(1e-9));
}

TEST_CASE("Order errors are unlearnt only when the display refused them", "[writer]") {
  WriterProfile learner = WriterProfile::foreign();
  learner.learning_rate = 0.5;
  RepetitionOutcome unnoticed;  // without guidance nothing refused the strokes out of order
  unnoticed.out_of_order_attempts = 3;
  CHECK(next_repetition_profile(learner, unnoticed).order_error_probability ==
        learner.order_error_probability);
  RepetitionOutcome refused;
  refused.guidance_share = 1.0;
  refused.out_of_order_attempts = 3;
  refused.refused_out_of_order = 3;
  CHECK(next_repetition_profile(learner, refused).order_error_probability ==
        Approx(learner.order_error_probability * std::exp(-0.5)));
  WriterLog log;
  WriterAttempt a;
  a.out_of_order = true;
  a.end = AttemptEnd::refused;
  log.attempts = {a, a};
  a.reversed = true;
  a.out_of_order = false;
  a.end = AttemptEnd::completed;
  log.attempts.push_back(a);
  const RepetitionOutcome from_log = RepetitionOutcome::from_log(log, 1.0);
  CHECK(from_log.out_of_order_attempts == 2);
  CHECK(from_log.refused_out_of_order == 2);
  CHECK(from_log.backwards_attempts == 1);
  CHECK(from_log.refused_backwards == 0);
}

TEST_CASE("A bad outcome is refused", "[writer]") {
  RepetitionOutcome outcome;
  outcome.guidance_share = 1.5;
  CHECK_THROWS_WITH(next_repetition_profile(WriterProfile::novice(), outcome),
                    Catch::Contains("guidance_share"));
  outcome.guidance_share = 0.5;
  outcome.refused_backwards = 2;
  CHECK_THROWS_AS(next_repetition_profile(WriterProfile::novice(), outcome), InvalidArgument);
}
