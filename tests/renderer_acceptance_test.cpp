// The renderer driven tick by tick by a pen that follows paths the engine did not make: the data's medians
// and person-like paths (sim/person_traces.hpp) on random characters of the whole hanzi-writer-data
// package. The renderer's verdict must be the stroke matcher's (analysis/stroke_matcher.hpp) for the same
// path: one rule of acceptance for every front-end.
#include <catch2/catch.hpp>
#include <cmath>
#include <iostream>
#include <random>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/sim/person_traces.hpp"
#include "corpus_folder.hpp"
#include "eval/stroke_acceptance.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;

namespace {

constexpr double kPeriod_s = 1e-3;
constexpr double kSpeed_m_s = 0.08;  // a brisk hand: 80 mm/s
constexpr double kDown_m = -0.0005;  // pressed 0.5 mm into the paper
constexpr double kUp_m = 0.005;

// A kinematic pen: ticks the renderer along `path` at kSpeed_m_s with the pen down, then lifts it. Returns
// the renderer's output at the lift.
struct Pen {
  Renderer& renderer;
  double time_s = 0.0;
  std::vector<PenSample>* trace = nullptr;  // when set, every tick as a pen trace (score.hpp's contact rule)

  RenderOutput at(const Vec2& p, double z, const Vec2& velocity) {
    DeviceState s;
    s.time_s = time_s;
    s.position_m = Vec3(p.x(), p.y(), z);
    s.velocity_m_s = Vec3(velocity.x(), velocity.y(), 0.0);
    if (trace != nullptr)
      trace->push_back({time_s, p, z - renderer.scene().layout.paper_z_m <= kPenContactThresholdM});
    time_s += kPeriod_s;
    return renderer.tick(s);
  }

  RenderOutput write(const std::vector<Vec2>& path) {
    at(path.front(), kUp_m, Vec2::Zero());
    at(path.front(), kDown_m, Vec2::Zero());
    for (std::size_t i = 1; i < path.size(); ++i) {
      const Vec2 step = path[i] - path[i - 1];
      const int ticks = std::max(1, static_cast<int>(std::ceil(step.norm() / (kSpeed_m_s * kPeriod_s))));
      const Vec2 velocity = step / (ticks * kPeriod_s);
      for (int k = 1; k <= ticks; ++k)
        at(path[i - 1] + step * (static_cast<double>(k) / ticks), kDown_m, velocity);
    }
    return at(path.back(), kUp_m, Vec2::Zero());
  }
};

ForceLawParameters no_guidance() {
  ForceLawParameters p;
  p.guidance = false;  // a kinematic pen: the force does not move it, and its verdict is what is tested
  return p;
}

}  // namespace

TEST_CASE("The data's medians written tick by tick at a hand's pace complete every stroke of 100 characters",
          "[stroke_progress][renderer]") {
  const CharacterLibrary library = CharacterLibrary::from_directory(testing::corpus_folder());
  std::vector<char32_t> characters =
      random_characters(library, 100, 7, CharacterLibrary::embedded().characters());
  characters = testing::sanitizer_subset(characters, 10, "characters written tick by tick");
  std::size_t strokes = 0;
  std::size_t completed = 0;
  std::size_t finished = 0;
  for (const char32_t c : characters) {
    const Scene scene = Scene::lay_out({library.load(c)});
    Renderer renderer(scene, no_guidance(), simulated_phantom_desktop_info());
    Pen pen{renderer};
    for (const PlacedStroke& stroke : scene.characters[0].strokes) {
      ++strokes;
      if (pen.write(stroke.median_m).stroke_completed) ++completed;
    }
    if (renderer.active().finished()) ++finished;
  }
  std::cout << "medians tick by tick: " << completed << " of " << strokes << " strokes, " << finished
            << " of " << characters.size() << " characters\n";
  CHECK(completed == strokes);
  CHECK(finished == characters.size());
}

TEST_CASE("The renderer and the stroke matcher give the same verdict on person-like paths",
          "[stroke_progress][renderer]") {
  const CharacterLibrary library = CharacterLibrary::from_directory(testing::corpus_folder());
  std::vector<char32_t> characters =
      random_characters(library, 60, 11, CharacterLibrary::embedded().characters());
  characters = testing::sanitizer_subset(characters, 6, "characters for the renderer-matcher comparison");
  std::size_t paths = 0;
  std::size_t agree = 0;
  std::size_t accepted = 0;
  for (const char32_t c : characters) {
    const Scene scene = Scene::lay_out({library.load(c)});
    const PlacedCharacter& character = scene.characters[0];
    std::mt19937_64 random(c);
    for (std::size_t s = 0; s < character.strokes.size(); ++s) {
      for (const TraceKind kind : {TraceKind::human, TraceKind::pointer, TraceKind::ends_short,
                                   TraceKind::half, TraceKind::reversed}) {
        const std::vector<Vec2> path = person_trace(character, s, kind, random);
        // A fresh renderer with the strokes before `s` written along their medians.
        Renderer renderer(scene, no_guidance(), simulated_phantom_desktop_info());
        Pen pen{renderer};
        for (std::size_t before = 0; before < s; ++before) pen.write(character.strokes[before].median_m);
        REQUIRE(renderer.active().stroke_index() == s);
        const bool rendered = pen.write(path).stroke_completed;
        const StrokeMatch match = match_stroke(character, s, path, scene.layout.start_radius_m);
        ++paths;
        if (rendered == match.accepted) ++agree;
        if (match.accepted) ++accepted;
      }
    }
  }
  std::cout << "renderer and matcher: " << agree << " of " << paths
            << " verdicts agree; the matcher accepted " << accepted << "\n";
  // The matcher reads a path as straight lines every 0.25 mm, the renderer every tick (0.08 mm at 80 mm/s):
  // a path right at a threshold may fall either side.
  CHECK(static_cast<double>(agree) >= 0.995 * static_cast<double>(paths));
  CHECK(accepted > paths / 3);  // both verdicts occur: the agreement is not vacuous
}

namespace {

// `path` moved `offset_m` across its own chord (to its left).
std::vector<Vec2> moved_across(const std::vector<Vec2>& path, double offset_m) {
  const Vec2 chord = (path.back() - path.front()).normalized();
  const Vec2 across(-chord.y(), chord.x());
  std::vector<Vec2> out;
  for (const Vec2& p : path) out.push_back(p + offset_m * across);
  return out;
}

}  // namespace

TEST_CASE(
    "A pen-down that never comes near the stroke's start is a miss: hinted after three, credited after five, "
    "as the score counts it",
    "[stroke_progress][renderer][stroke_assistance]") {
  // A learner with a mouse, whom nothing draws to the start, writes each stroke 8 mm beside itself: never
  // within the 5 mm start radius, so never WS. Each pen-down is a miss all the same (no dead end).
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  const PlacedCharacter& shi = scene.characters[0];
  Renderer renderer(scene, no_guidance(), simulated_phantom_desktop_info());
  std::vector<PenSample> trace;
  Pen pen{renderer, 0.0, &trace};
  const std::vector<Vec2> off = moved_across(shi.strokes[0].median_m, 0.008);
  REQUIRE((off.front() - shi.strokes[0].start()).norm() > scene.layout.start_radius_m);
  for (std::uint32_t miss = 1; miss <= 4; ++miss) {
    const RenderOutput out = pen.write(off);
    CHECK(out.missed_off_start);
    CHECK_FALSE(out.stroke_abandoned);  // nothing was begun in WS
    CHECK(out.refusal == StrokeRefusal::wrong_place);
    CHECK(out.misses == miss);
    CHECK(out.hint_shown == (miss >= 3));
    CHECK(out.stroke == 0);
  }
  // A touch that barely moves (0.5 mm) and a pen resting outside the box are no attempts.
  const Vec2 inside = shi.bounding_box.center();
  CHECK_FALSE(pen.write({inside, inside + Vec2(0.0005, 0.0)}).missed_off_start);
  const Vec2 outside = shi.bounding_box.max() + Vec2(0.01, 0.01);
  CHECK_FALSE(pen.write({outside, outside + Vec2(0.01, 0.0)}).missed_off_start);
  CHECK(renderer.active().misses() == 4);
  const RenderOutput fifth = pen.write(off);
  CHECK(fifth.missed_off_start);
  CHECK(fifth.stroke_assisted);
  CHECK(fifth.stroke == 1);
  CHECK(fifth.misses == 0);
  CHECK(pen.write(shi.strokes[1].median_m).stroke_completed);
  CHECK(renderer.active().finished());
  CHECK(renderer.active().strokes_assisted() == 1);
  CHECK(renderer.active().strokes_written() == 1);

  // The score of the same ticks credits the same stroke, judging the pen-downs the renderer counted.
  const CharacterScore score = score_trace(shi, trace);
  CHECK(score.strokes_assisted == 1);
  CHECK(score.strokes[0].assisted);
  CHECK_FALSE(score.strokes[1].assisted);
  CHECK(score.strokes_accepted == 1);
  CHECK(score.ignored_segments == 1);  // the touch

  // As records before version 8 ran (a miss only at a lift in WS): the same pen-downs are never misses.
  ForceLawParameters version_7 = no_guidance();
  version_7.acceptance.use_version_7_misses();
  Renderer old(scene, version_7, simulated_phantom_desktop_info());
  Pen old_pen{old};
  for (int k = 0; k < 6; ++k) {
    const RenderOutput out = old_pen.write(off);
    CHECK_FALSE(out.missed_off_start);
    CHECK(out.misses == 0);
    CHECK_FALSE(out.stroke_assisted);
  }
  CHECK(old.active().stroke_index() == 0);
}
