// The shares of the correction a trial's guidance takes from the hand (guidance_share.hpp), mode by mode:
// across the stroke the paper's fixture and fading as two springs, assist-as-needed only beyond its band,
// error amplification a negative share that enlarges the error within the field's bound, timing none; along
// the stroke only timing and replay.
#include "calligraphy/study/guidance_share.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/sim/writer_memory.hpp"

using namespace calligraphy;

namespace {

double shape_share(const ForceLawParameters& force, double hand_n_per_m, double deviation_m) {
  return guidance_shares(force, hand_n_per_m, deviation_m).shape;
}

ForceLawParameters mode(GuidanceMode m) {
  ForceLawParameters force;
  force.guidance_law = default_guidance_law(m);
  return force;
}

constexpr double kHand = 150.0;  // N/m

}  // namespace

TEST_CASE("Guidance takes the share of two springs, and off and timing take none", "[memory]") {
  const double fixed = shape_share(mode(GuidanceMode::fixed), kHand, 0.001);
  CHECK(fixed == Approx(400.0 / 550.0));
  ForceLawParameters off = mode(GuidanceMode::fixed);
  off.guidance = false;
  CHECK(shape_share(off, kHand, 0.001) == 0.0);
  CHECK(shape_share(mode(GuidanceMode::timing), kHand, 0.001) == 0.0);
  ForceLawParameters fading = mode(GuidanceMode::fading);
  std::get<FadingGuidance>(fading.guidance_law).gain = 0.5;
  CHECK(shape_share(fading, kHand, 0.001) == Approx(200.0 / 350.0));
}

TEST_CASE("Along the stroke only timing and replay take a share, that of their spring", "[memory]") {
  const double spring = 400.0 / 550.0;
  CHECK(guidance_shares(mode(GuidanceMode::timing), kHand, 0.001).timing == Approx(spring));
  ForceLawParameters replay = mode(GuidanceMode::replay);
  std::get<ReplayGuidance>(replay.guidance_law).teacher_trajectory = {TeacherSample{},
                                                                      TeacherSample{1.0, Vec3::Zero()}};
  const AssistanceShares replayed = guidance_shares(replay, kHand, 0.001);
  CHECK(replayed.timing == Approx(spring));
  CHECK(replayed.shape == Approx(spring));
  // Both move the pen in time: they demonstrate the timing they take.
  CHECK(replayed.timing_demonstration == Approx(spring));
  CHECK(guidance_shares(mode(GuidanceMode::timing), kHand, 0.001).timing_demonstration == Approx(spring));
  CHECK(guidance_shares(mode(GuidanceMode::fixed), kHand, 0.001).timing_demonstration == 0.0);
  for (const GuidanceMode m : {GuidanceMode::fixed, GuidanceMode::fading, GuidanceMode::assist_as_needed,
                               GuidanceMode::error_amplification}) {
    CAPTURE(to_string(m));
    CHECK(guidance_shares(mode(m), kHand, 0.002).timing == 0.0);  // they pull towards the nearest point
  }
  ForceLawParameters off = mode(GuidanceMode::timing);
  off.guidance = false;
  CHECK(guidance_shares(off, kHand, 0.001).timing == 0.0);
}

TEST_CASE("Assist-as-needed takes the share of the deviation beyond its band", "[memory]") {
  ForceLawParameters assist = mode(GuidanceMode::assist_as_needed);
  std::get<AssistAsNeededGuidance>(assist.guidance_law).band_m = 0.001;
  const double full = shape_share(mode(GuidanceMode::fixed), kHand, 0.002);
  CHECK(shape_share(assist, kHand, 0.0005) == 0.0);  // within the band: the writer's own
  CHECK(shape_share(assist, kHand, 0.002) == Approx(0.5 * full));
  CHECK(shape_share(assist, kHand, 0.004) == Approx(0.75 * full));
  CHECK(shape_share(assist, kHand, std::nan("")) == Approx(full));  // nothing written: all help
}

TEST_CASE("Error amplification enlarges the error the writer learns from, within its force bound",
          "[memory]") {
  ForceLawParameters amplify = mode(GuidanceMode::error_amplification);
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).gain = 0.25;  // 100 N/m against the hand's 150
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).max_force_n = 1.0;
  // Unsaturated: k / (k - g K) = 3, a share of -2.
  CHECK(shape_share(amplify, kHand, 0.001) == Approx(-2.0));
  // Saturated at 0.3 N: 1 + F / (k e) = 1 + 0.3 / (150 x 0.004) = 1.5.
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).max_force_n = 0.3;
  CHECK(shape_share(amplify, kHand, 0.004) == Approx(-0.5));
  // A field stiffer than the hand is held by its bound; never below the memory's guard.
  std::get<ErrorAmplificationGuidance>(amplify.guidance_law).gain = 1.0;
  CHECK(shape_share(amplify, kHand, 0.004) == Approx(-0.5));
  CHECK(shape_share(amplify, kHand, 0.0) == Approx(kMinAssistanceShare));
  CHECK(shape_share(amplify, kHand, std::nan("")) == 0.0);
  // A negative share teaches more than none: the two-state memory learns faster from the enlarged error.
  WriterMemory amplified, unguided;
  practise(amplified, {1, 2}, U"十", guidance_shares(amplify, kHand, 0.004));
  practise(unguided, {1, 2}, U"十", {});
  CHECK(shape_skill(amplified, {1, 2}) > shape_skill(unguided, {1, 2}));
}

TEST_CASE("A bad hand or deviation is refused naming it", "[memory]") {
  CHECK_THROWS_WITH(shape_share(mode(GuidanceMode::fixed), 0.0, 0.001), Catch::Contains("hand stiffness"));
  CHECK_THROWS_WITH(shape_share(mode(GuidanceMode::fixed), kHand, -0.001), Catch::Contains("mean deviation"));
  CHECK_THROWS_AS(
      practise(*std::make_unique<WriterMemory>(), {1}, U"一", {.shape = kMinAssistanceShare - 1.0}),
      InvalidArgument);
}
