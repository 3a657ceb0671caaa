// The writer's memory (writer_memory.hpp): the two-state model's learning and forgetting, the error that
// guidance takes away (slacking), shape and timing learned apart, consolidation between sessions, transfer
// through typical strokes.
#include "calligraphy/sim/writer_memory.hpp"

#include <catch2/catch.hpp>
#include <cmath>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

namespace {

// The skill of one typical stroke after `trials` trials of one stroke each with assistance `share`.
double skill_after(int trials, double share) {
  WriterMemory memory;
  for (int i = 0; i < trials; ++i) practise(memory, {1}, U"十", {.shape = share});
  return memory.typical_strokes.at(1).skill();
}

}  // namespace

TEST_CASE("the two-state model learns by its rates and the closed form", "[sim][memory]") {
  const TwoStateRates rates;
  WriterMemory memory;
  practise(memory, {1}, U"十", {});
  // First trial from 0: the error is 1, so x_f = B_f and x_s = B_s.
  CHECK(memory.typical_strokes.at(1).fast == Approx(rates.fast_learning));
  CHECK(memory.typical_strokes.at(1).slow == Approx(rates.slow_learning));
  // Second: x' = A x + B (1 - x_f - x_s) per state.
  practise(memory, {1}, U"十", {});
  const double x = rates.fast_learning + rates.slow_learning;
  CHECK(memory.typical_strokes.at(1).fast ==
        Approx(rates.fast_retention * rates.fast_learning + rates.fast_learning * (1 - x)));
  CHECK(memory.typical_strokes.at(1).slow ==
        Approx(rates.slow_retention * rates.slow_learning + rates.slow_learning * (1 - x)));
  // Practice raises the skill, by ever smaller steps over equal numbers of trials, and never past 1.
  double previous = 0.0, step = 1.0;
  for (int n = 40; n <= 400; n += 40) {
    const double now = skill_after(n, 0.0);
    CHECK(now > previous);
    CHECK(now <= 1.0);
    CHECK(now - previous < step);
    step = now - previous;
    previous = now;
  }
}

TEST_CASE("guidance that corrects for the writer leaves less learned (slacking)", "[sim][memory]") {
  const double alone = skill_after(30, 0.0);
  const double half = skill_after(30, guidance_assistance_share(1.0, 150.0, 150.0));
  const double fixture = skill_after(30, guidance_assistance_share(1.0, 600.0, 150.0));
  CHECK(guidance_assistance_share(1.0, 150.0, 150.0) == Approx(0.5));
  CHECK(guidance_assistance_share(0.0, 600.0, 150.0) == 0.0);
  CHECK(alone > half);
  CHECK(half > fixture);
  CHECK(fixture > 0.0);
  CHECK_THROWS_AS(guidance_assistance_share(1.5, 600.0, 150.0), InvalidArgument);
  CHECK_THROWS_AS(guidance_assistance_share(1.0, 600.0, 0.0), InvalidArgument);
  WriterMemory memory;
  // A negative share is an error a repulsive field enlarged (error amplification), down to the guard.
  CHECK_NOTHROW(practise(memory, {1}, U"十", {.shape = -0.1}));
  CHECK_THROWS_AS(practise(memory, {1}, U"十", {.shape = kMinAssistanceShare - 0.1}), InvalidArgument);
  CHECK_THROWS_AS(practise(memory, {1}, U"十", {.shape = 1.1}), InvalidArgument);
  CHECK_THROWS_WITH(practise(memory, {1}, U"十", {.timing = 1.1}), Catch::Contains("timing"));
}

TEST_CASE("between sessions the fast state is gone and the slow one kept, and unpractised skills decay",
          "[sim][memory]") {
  WriterMemory memory;
  for (int i = 0; i < 20; ++i) practise(memory, {1, 2}, U"十", {});
  const SkillMemory before = memory.typical_strokes.at(1);
  consolidate(memory);
  CHECK(memory.typical_strokes.at(1).fast == 0.0);
  CHECK(memory.typical_strokes.at(1).slow == before.slow);
  CHECK(memory.typical_strokes.at(1).skill() < before.skill());
  // Writing other strokes lets stroke 1 decay by the retention factors.
  const SkillMemory kept = memory.typical_strokes.at(1);
  practise(memory, {3}, U"人", {});
  CHECK(memory.typical_strokes.at(1).slow == Approx(kept.slow * TwoStateRates{}.slow_retention));
  CHECK(memory.stroke_timing.at(1).fast == 0.0);  // timing consolidates alike
  CHECK(memory.stroke_timing.at(1).slow > 0.0);
}

TEST_CASE("shape and timing learn apart, each from the error its own guidance left", "[sim][memory]") {
  // A fixture corrects shape only, a moving target timing only; without guidance timing learns from the
  // share of its error the writer sees (kSeenTimingShare), shape from all of it.
  WriterMemory alone, fixture, paced;
  for (int i = 0; i < 30; ++i) {
    practise(alone, {1, 2}, U"十", {});
    practise(fixture, {1, 2}, U"十", {.shape = 0.73});
    practise(paced, {1, 2}, U"十", {.timing = 0.73});
  }
  CHECK(timing_skill(alone, {1, 2}) < shape_skill(alone, {1, 2}));
  CHECK(shape_skill(fixture, {1, 2}) < shape_skill(alone, {1, 2}));
  CHECK(timing_skill(fixture, {1, 2}) == timing_skill(alone, {1, 2}));
  CHECK(order_skill(fixture, U"十") < order_skill(alone, U"十"));  // order learns with the shape share
  CHECK(timing_skill(paced, {1, 2}) < timing_skill(alone, {1, 2}));
  CHECK(shape_skill(paced, {1, 2}) == shape_skill(alone, {1, 2}));
  const WriterSkills skills = writer_skills(paced, {1, 2}, U"十");
  CHECK(skills.shape == shape_skill(paced, {1, 2}));
  CHECK(skills.order == order_skill(paced, U"十"));
  CHECK(skills.timing == timing_skill(paced, {1, 2}));
  CHECK(timing_skill(paced, {21}) == 0.0);  // never written
}

TEST_CASE("a character not practised starts from what its typical strokes learned elsewhere",
          "[sim][memory]") {
  WriterMemory memory;
  // 十 (typical strokes 1, 2) and 人 (3, 5) practised; 木 is 1, 2, 3, 5 and 山 is 2, 21, 2.
  for (int i = 0; i < 10; ++i) {
    practise(memory, {1, 2}, U"十", {});
    practise(memory, {3, 5}, U"人", {});
  }
  CHECK(shape_skill(memory, {1, 2, 3, 5}) > 0.0);
  CHECK(shape_skill(memory, {1, 2, 3, 5}) > shape_skill(memory, {2, 21, 2}));
  CHECK(shape_skill(memory, {21}) == 0.0);
  CHECK(order_skill(memory, U"木") == 0.0);  // its order was never practised
  CHECK(order_skill(memory, U"十") > 0.0);
}

TEST_CASE("the learned profile moves from the writer's own to the skilled writer's", "[sim][memory]") {
  const WriterProfile own = WriterProfile::foreign();
  const WriterProfile skilled = WriterProfile::skilled();
  const WriterProfile none = learned_profile(own, skilled, {});
  CHECK(none.bias_offset_m == own.bias_offset_m);
  CHECK(none.order_error_probability == own.order_error_probability);
  const WriterProfile all = learned_profile(own, skilled, {1.0, 1.0, 1.0});
  CHECK(all.bias_offset_m == Approx(skilled.bias_offset_m));
  CHECK(all.backwards_probability == Approx(skilled.backwards_probability));
  CHECK(all.hand_stiffness_n_per_m == own.hand_stiffness_n_per_m);  // the hand itself does not change
  CHECK(all.writing_speed_m_s == Approx(skilled.writing_speed_m_s));
  const WriterProfile half = learned_profile(own, skilled, {.shape = 0.5});
  CHECK(half.bias_offset_m == Approx((own.bias_offset_m + skilled.bias_offset_m) / 2));
  CHECK(half.order_error_probability == own.order_error_probability);
  CHECK(half.writing_speed_m_s == own.writing_speed_m_s);  // speed and pauses follow timing, not shape
  CHECK(half.hesitation_probability == own.hesitation_probability);
  const WriterProfile paced = learned_profile(own, skilled, {.timing = 0.5});
  CHECK(paced.writing_speed_m_s == Approx((own.writing_speed_m_s + skilled.writing_speed_m_s) / 2));
  CHECK(paced.hesitation_probability ==
        Approx((own.hesitation_probability + skilled.hesitation_probability) / 2));
  CHECK(paced.bias_offset_m == own.bias_offset_m);
  CHECK_THROWS_AS(learned_profile(own, skilled, {.shape = 1.5}), InvalidArgument);
  CHECK_THROWS_WITH(learned_profile(own, skilled, {.timing = -0.1}), Catch::Contains("timing"));
  for (const std::string& field : learned_profile_fields()) {
    CHECK_NOTHROW(writer_parameter(all, field));
  }
}

TEST_CASE("a demonstrated time course teaches timing more than vision, and takes shape as a fixture does",
          "[sim][memory]") {
  // A replay moves the pen at the teacher's time: it takes h of both corrections and demonstrates the timing
  // (guidance_shares gives shape = timing = demonstration = K / (K + k)).
  constexpr double h = 0.73;
  WriterMemory seen, replayed;
  for (int i = 0; i < 30; ++i) {
    practise(seen, {1, 2}, U"十", {});
    practise(replayed, {1, 2}, U"十", {.shape = h, .timing = h, .timing_demonstration = h});
  }
  CHECK(timing_skill(replayed, {1, 2}) > timing_skill(seen, {1, 2}));  // Feygin et al. 2002's direction
  CHECK(shape_skill(replayed, {1, 2}) < shape_skill(seen, {1, 2}));    // the guidance hypothesis for shape
  // First trial from 0: the timing error is what is seen of what is left plus what was demonstrated.
  WriterMemory one;
  practise(one, {1}, U"十", {.timing = h, .timing_demonstration = h});
  CHECK(one.stroke_timing.at(1).fast ==
        Approx(TwoStateRates{}.fast_learning * (kSeenTimingShare * (1 - h) + h)));
  CHECK_THROWS_WITH(practise(one, {1}, U"十", {.timing_demonstration = 1.5}),
                    Catch::Contains("demonstration"));
}
