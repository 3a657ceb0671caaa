// quiz_characters: a trial's trace judged by the quiz per character (trial/quiz_trace.hpp), over 十口.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstddef>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/trial/quiz_trace.hpp"

using namespace calligraphy;

namespace {

// 十 (strokes 0 and 1 of the scene) then 口 (strokes 2, 3 and 4), on a paper 20 mm above the device's origin.
Scene shi_kou() {
  SceneLayout layout;
  layout.paper_z_m = 0.02;
  return Scene::lay_out({CharacterLibrary::embedded().load(U'十'), CharacterLibrary::embedded().load(U'口')},
                        layout);
}

// A trace written tick by tick at 1 kHz, as the recorder keeps it: the HIP and the active stroke.
struct TraceWriter {
  const Scene& scene;
  std::vector<TrialSample> trace;
  double time_s = 0.0;

  void tick(const Vec2& p, double height_m, std::size_t active_stroke) {
    TrialSample s;
    s.time_s = time_s;
    s.position_m = Vec3(p.x(), p.y(), scene.layout.paper_z_m + height_m);
    s.stroke = active_stroke;
    trace.push_back(s);
    time_s += 1e-3;
  }
  // Writes the reference stroke `stroke` of `character` at `height_m` above the paper with `active_stroke`
  // as the renderer's active stroke, then lifts the pen 10 mm.
  void write(std::size_t character, std::size_t stroke, double height_m, std::size_t active_stroke) {
    const std::vector<Vec2> points =
        reference_polyline_m(scene.characters[character].strokes[stroke].elements, 0.5e-3, 4096);
    for (const Vec2& p : points) tick(p, height_m, active_stroke);
    tick(points.back(), 0.01, active_stroke);
    time_s += 0.2;
  }
};

std::size_t count(const std::vector<QuizEvent>& events, QuizEvent::Kind kind) {
  return static_cast<std::size_t>(
      std::count_if(events.begin(), events.end(), [kind](const QuizEvent& e) { return e.kind == kind; }));
}

}  // namespace

TEST_CASE("quiz_characters judges each character's ticks with that character's quiz", "[trial][quiz]") {
  const Scene scene = shi_kou();
  REQUIRE(scene.characters.size() == 2);
  REQUIRE(scene.characters[0].strokes.size() == 2);
  REQUIRE(scene.characters[1].strokes.size() == 3);
  TraceWriter writer{scene, {}};
  for (std::size_t k = 0; k < 2; ++k) writer.write(0, k, 0.0, k);
  for (std::size_t k = 0; k < 3; ++k) writer.write(1, k, 0.0, 2 + k);

  const std::vector<std::vector<QuizEvent>> events = quiz_characters(scene, writer.trace, QuizOptions{});
  REQUIRE(events.size() == 2);
  CHECK(count(events[0], QuizEvent::Kind::stroke_accepted) == 2);
  CHECK(count(events[1], QuizEvent::Kind::stroke_accepted) == 3);
  for (const std::vector<QuizEvent>& character : events) {
    CHECK(count(character, QuizEvent::Kind::stroke_missed) == 0);
    REQUIRE_FALSE(character.empty());
    CHECK(character.back().kind == QuizEvent::Kind::character_completed);
  }
  // Each character's verdicts come from its own ticks: 十's before 口's first pen-down tick.
  const auto first_kou = std::find_if(writer.trace.begin(), writer.trace.end(),
                                      [](const TrialSample& s) { return s.stroke >= 2; });
  REQUIRE(first_kou != writer.trace.end());
  for (const QuizEvent& e : events[0]) CHECK(e.time_s < first_kou->time_s);
  for (const QuizEvent& e : events[1]) CHECK(e.time_s >= first_kou->time_s);
}

TEST_CASE("quiz_characters gives the ticks after the last stroke to the last character", "[trial][quiz]") {
  const Scene scene = shi_kou();
  TraceWriter writer{scene, {}};
  for (std::size_t k = 0; k < 2; ++k) writer.write(0, k, 0.0, k);
  // The renderer's active stroke is one past the scene's last: 口 is still judged, by 口's quiz.
  for (std::size_t k = 0; k < 3; ++k) writer.write(1, k, 0.0, 5);
  const std::vector<std::vector<QuizEvent>> events = quiz_characters(scene, writer.trace, QuizOptions{});
  REQUIRE(events.size() == 2);
  CHECK(count(events[0], QuizEvent::Kind::character_completed) == 1);
  CHECK(count(events[1], QuizEvent::Kind::stroke_accepted) == 3);
  CHECK(count(events[1], QuizEvent::Kind::character_completed) == 1);
}

TEST_CASE("quiz_characters takes the pen as down within kPenContactThresholdM above the paper",
          "[trial][quiz]") {
  const Scene scene = shi_kou();
  const auto kou_events = [&](double height_m) {
    TraceWriter writer{scene, {}};
    for (std::size_t k = 0; k < 2; ++k) writer.write(0, k, 0.0, k);
    for (std::size_t k = 0; k < 3; ++k) writer.write(1, k, height_m, 2 + k);
    return quiz_characters(scene, writer.trace, QuizOptions{}).at(1);
  };
  const std::vector<QuizEvent> touching = kou_events(0.8 * kPenContactThresholdM);
  CHECK(count(touching, QuizEvent::Kind::stroke_accepted) == 3);
  CHECK(kou_events(1.2 * kPenContactThresholdM).empty());  // never down: nothing written, nothing judged
}
