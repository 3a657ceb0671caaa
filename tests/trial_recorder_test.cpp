// The recorder reports a deviation only where the pen wrote: a stroke without a WS tick in its last
// attempt has none (nullopt), never a 0 that would read as a perfect stroke.
#include <catch2/catch.hpp>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/recorder.hpp"

using namespace calligraphy;

namespace {

Scene scene_of_shi() { return Scene::lay_out({CharacterLibrary::embedded().load(U'十')}); }

// Feeds ticks to a recorder, 1 ms apart, with the pen `offset_m` to the side of the first stroke's start.
class Ticks {
 public:
  explicit Ticks(const Scene& scene) : scene_(scene), recorder_(scene) {}
  void tick(InteractionState state, bool completed = false, bool abandoned = false, double offset_m = 0.0) {
    DeviceState device;
    device.time_s = 1e-3 * static_cast<double>(count_++);
    const Vec2 start = scene_.characters[0].strokes[0].start();
    device.position_m = Vec3(start.x(), start.y() + offset_m, 0.0);
    RenderOutput output;
    output.state = state;
    output.state_changed = state != last_;
    output.stroke_completed = completed;
    output.stroke_abandoned = abandoned;
    last_ = state;
    recorder_.record(device, output);
  }
  TrialRecorder& recorder() { return recorder_; }

 private:
  const Scene& scene_;
  TrialRecorder recorder_;
  std::size_t count_ = 0;
  InteractionState last_ = InteractionState::separation;
};

}  // namespace

TEST_CASE("A trial in which nothing is written has no deviations", "[recorder]") {
  const Scene scene = scene_of_shi();
  Ticks ticks(scene);
  for (int i = 0; i < 100; ++i) ticks.tick(InteractionState::separation);
  ticks.recorder().finish(0.1);
  const TrialMetrics& m = ticks.recorder().metrics();
  CHECK_FALSE(m.mean_deviation_m.has_value());
  CHECK_FALSE(m.max_deviation_m.has_value());
  REQUIRE(m.per_stroke.size() == 2);
  for (const StrokeMetrics& s : m.per_stroke) {
    CHECK_FALSE(s.mean_deviation_m.has_value());
    CHECK_FALSE(s.max_deviation_m.has_value());
  }
}

TEST_CASE("An abandoned attempt leaves no deviation and one under way at the end counts", "[recorder]") {
  const Scene scene = scene_of_shi();
  SECTION("abandoned last attempt") {
    Ticks ticks(scene);
    for (int i = 0; i < 20; ++i) ticks.tick(InteractionState::writing, false, false, 0.002);
    ticks.tick(InteractionState::separation, false, true);  // lifted in WS: the stroke is reloaded
    ticks.tick(InteractionState::separation);
    ticks.recorder().finish(0.1);
    const TrialMetrics& m = ticks.recorder().metrics();
    CHECK(m.per_stroke[0].attempts == 1);
    CHECK_FALSE(m.per_stroke[0].mean_deviation_m.has_value());
    CHECK_FALSE(m.mean_deviation_m.has_value());
  }
  SECTION("attempt under way when the trial ends") {
    Ticks ticks(scene);
    for (int i = 0; i < 20; ++i) ticks.tick(InteractionState::writing, false, false, 0.002);
    ticks.recorder().finish(0.1);
    const TrialMetrics& m = ticks.recorder().metrics();
    REQUIRE(m.per_stroke[0].mean_deviation_m.has_value());
    CHECK(*m.per_stroke[0].mean_deviation_m == Approx(0.002).margin(1e-9));  // 2 mm beside the start
    CHECK(m.mean_deviation_m == m.per_stroke[0].mean_deviation_m);
    CHECK(m.max_deviation_m == m.per_stroke[0].max_deviation_m);
    CHECK_FALSE(m.per_stroke[0].completed);
    CHECK_FALSE(m.per_stroke[1].mean_deviation_m.has_value());  // never reached
  }
}

TEST_CASE("A completed stroke on the reference has a deviation of zero, present", "[recorder]") {
  const Scene scene = scene_of_shi();
  Ticks ticks(scene);
  for (int i = 0; i < 5; ++i) ticks.tick(InteractionState::writing);
  ticks.tick(InteractionState::writing, true);
  ticks.recorder().finish(0.1);
  const TrialMetrics& m = ticks.recorder().metrics();
  REQUIRE(m.per_stroke[0].mean_deviation_m.has_value());
  CHECK(*m.per_stroke[0].max_deviation_m == Approx(0.0).margin(1e-12));
  CHECK(m.per_stroke[0].completed);
  CHECK_FALSE(m.per_stroke[1].mean_deviation_m.has_value());
}

TEST_CASE("take_trace hands over every recorded tick and leaves the recorder's trace empty", "[recorder]") {
  const Scene scene = scene_of_shi();
  Ticks ticks(scene);
  for (int i = 0; i < 250; ++i) ticks.tick(InteractionState::separation);
  const std::vector<TrialSample> copy = ticks.recorder().trace();
  const std::vector<TrialSample> taken = ticks.recorder().take_trace();
  REQUIRE(taken.size() == 250);
  CHECK(taken.back().time_s == copy.back().time_s);
  CHECK(taken[17].position_m == copy[17].position_m);
  CHECK(ticks.recorder().trace().empty());
}
