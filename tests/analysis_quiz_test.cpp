// QuizSession on hand-made pen traces over 十 (horizontal, then vertical) and 口.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "embedded_scenes.hpp"

using namespace calligraphy;

namespace {

const PlacedCharacter& character_of(char32_t c) { return testing::embedded_scene(c).characters.front(); }

// The reference stroke as points 0.5 mm apart, shifted by `offset_m`, optionally reversed.
std::vector<Vec2> stroke_points(const PlacedStroke& stroke, const Vec2& offset_m = Vec2::Zero(),
                                bool reversed = false) {
  std::vector<Vec2> points = reference_polyline_m(stroke.elements, 0.5e-3, 4096);
  for (Vec2& p : points) p += offset_m;
  if (reversed) std::reverse(points.begin(), points.end());
  return points;
}

// Feeds a pen-down run of `points` at 1 kHz and one pen-up sample; returns the events of the lift.
struct Writer {
  QuizSession quiz;
  double time_s = 0.0;
  std::vector<QuizEvent> write(const std::vector<Vec2>& points) {
    for (const Vec2& p : points) {
      REQUIRE(quiz.feed({time_s, p, true}).empty());
      time_s += 1e-3;
    }
    const std::vector<QuizEvent> events = quiz.feed({time_s, points.back(), false});
    time_s += 0.2;
    return events;
  }
};

bool has(const std::vector<QuizEvent>& events, QuizEvent::Kind kind) {
  return std::any_of(events.begin(), events.end(), [kind](const QuizEvent& e) { return e.kind == kind; });
}

}  // namespace

TEST_CASE("quiz accepts the strokes written in order and completes the character", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  REQUIRE(shi.strokes.size() == 2);
  Writer writer{QuizSession(shi)};
  const auto first = writer.write(stroke_points(shi.strokes[0]));
  REQUIRE(first.size() == 1);
  CHECK(first[0].kind == QuizEvent::Kind::stroke_accepted);
  CHECK(first[0].stroke == 0);
  CHECK_FALSE(first[0].backwards);
  CHECK(first[0].refusal == StrokeRefusal::none);
  CHECK_FALSE(first[0].written_stroke);
  CHECK(writer.quiz.current_stroke() == 1);
  const auto second = writer.write(stroke_points(shi.strokes[1]));
  CHECK(has(second, QuizEvent::Kind::stroke_accepted));
  CHECK(has(second, QuizEvent::Kind::character_completed));
  CHECK(writer.quiz.complete());
  CHECK(writer.quiz.total_misses() == 0);
  // Samples after completion change nothing.
  CHECK(writer.write(stroke_points(shi.strokes[1])).empty());
}

TEST_CASE("quiz misses a stroke written out of order and hints after the set number of misses",
          "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  QuizOptions options;
  options.hint_after_misses = 2;
  Writer writer{QuizSession(shi, options)};
  const auto first = writer.write(stroke_points(shi.strokes[1]));  // the vertical before the horizontal
  REQUIRE(first.size() == 1);
  CHECK(first[0].kind == QuizEvent::Kind::stroke_missed);
  CHECK(first[0].stroke == 0);
  CHECK(first[0].misses_on_stroke == 1);
  CHECK(first[0].refusal == StrokeRefusal::wrong_order);
  CHECK(first[0].written_stroke == 1u);
  const auto second = writer.write(stroke_points(shi.strokes[1]));
  CHECK(has(second, QuizEvent::Kind::stroke_missed));
  CHECK(has(second, QuizEvent::Kind::hint));
  const auto third = writer.write(stroke_points(shi.strokes[1]));
  CHECK(has(third, QuizEvent::Kind::hint));  // after each further miss too
  CHECK(writer.quiz.total_misses() == 3);
  // The right stroke is then accepted and the count of misses on the stroke starts again.
  const auto right = writer.write(stroke_points(shi.strokes[0]));
  CHECK(has(right, QuizEvent::Kind::stroke_accepted));
  CHECK(writer.quiz.misses_on_stroke() == 0);
  CHECK(writer.quiz.total_misses() == 3);
}

TEST_CASE("quiz hints after the stroke acceptance's hint_after_misses unless an option overrides it",
          "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  // Misses (the vertical before the horizontal) until the first hint; 0 when none came in `most` misses.
  const auto misses_to_hint = [&](const QuizOptions& options, int most) {
    Writer writer{QuizSession(shi, options)};
    for (int miss = 1; miss <= most; ++miss) {
      if (has(writer.write(stroke_points(shi.strokes[1])), QuizEvent::Kind::hint)) return miss;
    }
    return 0;
  };
  QuizOptions options;
  // One definition: without an override the quiz takes the acceptance's value and its default.
  CHECK(!options.hint_after_misses.has_value());
  CHECK(options.hint_after() == static_cast<int>(StrokeAcceptance{}.hint_after_misses));
  CHECK(misses_to_hint(options, 6) == static_cast<int>(StrokeAcceptance{}.hint_after_misses));
  options.acceptance.hint_after_misses = 4;
  CHECK(misses_to_hint(options, 6) == 4);
  options.acceptance.hint_after_misses = 0;  // never
  CHECK(misses_to_hint(options, 6) == 0);
  // The option overrides the acceptance's, whatever it is.
  options.hint_after_misses = 1;
  CHECK(options.hint_after() == 1);
  CHECK(misses_to_hint(options, 6) == 1);
  // Its range is the acceptance's table's.
  const ParameterRange range = parameter_field(&StrokeAcceptance::hint_after_misses).range;
  options.hint_after_misses = static_cast<int>(range.high);
  CHECK_NOTHROW(options.validate());
  options.hint_after_misses = static_cast<int>(range.high) + 1;
  CHECK_THROWS_AS(options.validate(), InvalidArgument);
  options.hint_after_misses = -1;
  CHECK_THROWS_AS(options.validate(), InvalidArgument);
}

namespace {

std::vector<QuizEvent::Kind> kinds(const std::vector<QuizEvent>& events) {
  std::vector<QuizEvent::Kind> out;
  for (const QuizEvent& e : events) out.push_back(e.kind);
  return out;
}

}  // namespace

TEST_CASE(
    "quiz credits a stroke assisted after the acceptance's assist_after_misses misses, then expects the next",
    "[analysis][quiz]") {
  using K = QuizEvent::Kind;
  const PlacedCharacter& shi = character_of(U'十');
  // The default: a hint after 3 misses and after the 4th, the credit after the 5th (StrokeAcceptance), no
  // hint beside it: the stroke is shown as assisted instead.
  REQUIRE(QuizOptions{}.assist_after() == 5);
  REQUIRE(QuizOptions{}.hint_after() == 3);
  Writer writer{QuizSession(shi)};
  const std::vector<std::vector<K>> expected = {{K::stroke_missed},
                                                {K::stroke_missed},
                                                {K::stroke_missed, K::hint},
                                                {K::stroke_missed, K::hint},
                                                {K::stroke_missed, K::stroke_assisted}};
  std::vector<QuizEvent> fifth;
  for (std::size_t miss = 0; miss < expected.size(); ++miss) {
    INFO("miss " << miss + 1);
    const std::vector<QuizEvent> events = writer.write(stroke_points(shi.strokes[1]));  // out of order
    CHECK(kinds(events) == expected[miss]);
    CHECK(events.front().misses_on_stroke == static_cast<int>(miss) + 1);
    CHECK(events.front().refusal == StrokeRefusal::wrong_order);
    if (miss + 1 < expected.size()) CHECK(writer.quiz.current_stroke() == 0);
    fifth = events;
  }
  REQUIRE(fifth.size() == 2);
  const QuizEvent& credit = fifth[1];
  CHECK(credit.stroke == 0);
  CHECK(credit.misses_on_stroke == 5);  // the misses that earned it, as Hanzi Writer's onCorrectStroke
  CHECK(credit.total_misses == 5);
  CHECK(credit.refusal == StrokeRefusal::none);
  CHECK_FALSE(credit.written_stroke);
  CHECK(credit.time_s == fifth[0].time_s);
  CHECK(writer.quiz.current_stroke() == 1);
  CHECK(writer.quiz.misses_on_stroke() == 0);
  CHECK(writer.quiz.strokes_assisted() == 1);
  CHECK_FALSE(writer.quiz.complete());
  // The next stroke written is accepted in its turn, and completes the character.
  const std::vector<QuizEvent> next = writer.write(stroke_points(shi.strokes[1]));
  CHECK(kinds(next) == std::vector<K>{K::stroke_accepted, K::character_completed});
  CHECK(next[0].stroke == 1);
  CHECK(next[0].total_misses == 5);
  CHECK(writer.quiz.complete());
  CHECK(writer.quiz.events().size() == 1 + 1 + 2 + 2 + 2 + 2);

  // At 3 the credit replaces the hint that would come with the 3rd miss.
  QuizOptions three;
  three.acceptance.assist_after_misses = 3;
  Writer sooner{QuizSession(shi, three)};
  CHECK(kinds(sooner.write(stroke_points(shi.strokes[1]))) == std::vector<K>{K::stroke_missed});
  CHECK(kinds(sooner.write(stroke_points(shi.strokes[1]))) == std::vector<K>{K::stroke_missed});
  CHECK(kinds(sooner.write(stroke_points(shi.strokes[1]))) ==
        std::vector<K>{K::stroke_missed, K::stroke_assisted});
  CHECK(sooner.quiz.current_stroke() == 1);
  // A hint overridden to come sooner still comes before the credit.
  three.hint_after_misses = 2;
  Writer hinted{QuizSession(shi, three)};
  CHECK(kinds(hinted.write(stroke_points(shi.strokes[1]))) == std::vector<K>{K::stroke_missed});
  CHECK(kinds(hinted.write(stroke_points(shi.strokes[1]))) == std::vector<K>{K::stroke_missed, K::hint});
  CHECK(kinds(hinted.write(stroke_points(shi.strokes[1]))) ==
        std::vector<K>{K::stroke_missed, K::stroke_assisted});

  // At 0 never: the stroke stays expected, hinted after each miss from the 3rd.
  QuizOptions never;
  never.acceptance.assist_after_misses = 0;
  Writer stuck{QuizSession(shi, never)};
  for (int miss = 1; miss <= 12; ++miss) {
    const std::vector<QuizEvent> events = stuck.write(stroke_points(shi.strokes[1]));
    CHECK_FALSE(has(events, K::stroke_assisted));
    CHECK(has(events, K::hint) == (miss >= 3));
  }
  CHECK(stuck.quiz.current_stroke() == 0);
  CHECK(stuck.quiz.strokes_assisted() == 0);
  CHECK(stuck.quiz.total_misses() == 12);
}

TEST_CASE("quiz completes the character when its last stroke is credited assisted", "[analysis][quiz]") {
  using K = QuizEvent::Kind;
  const PlacedCharacter& shi = character_of(U'十');
  QuizOptions options;
  options.acceptance.assist_after_misses = 2;
  Writer writer{QuizSession(shi, options)};
  CHECK(kinds(writer.write(stroke_points(shi.strokes[0]))) == std::vector<K>{K::stroke_accepted});
  // The horizontal again where the vertical is expected: missed twice, then credited and complete.
  CHECK(kinds(writer.write(stroke_points(shi.strokes[0]))) == std::vector<K>{K::stroke_missed});
  const std::vector<QuizEvent> last = writer.write(stroke_points(shi.strokes[0]));
  CHECK(kinds(last) == std::vector<K>{K::stroke_missed, K::stroke_assisted, K::character_completed});
  CHECK(last[1].stroke == 1);
  CHECK(last[2].stroke == 1);
  CHECK(last[2].total_misses == 2);
  CHECK(writer.quiz.complete());
  CHECK(writer.quiz.strokes_assisted() == 1);
  CHECK(writer.write(stroke_points(shi.strokes[1])).empty());  // nothing more is judged
  CHECK(std::string(to_string(K::stroke_assisted)) == "stroke_assisted");
}

TEST_CASE("quiz reports a stroke written backwards and accepts it only when asked to", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  Writer strict{QuizSession(shi)};
  const auto events = strict.write(stroke_points(shi.strokes[0], Vec2::Zero(), true));
  REQUIRE_FALSE(events.empty());
  CHECK(events[0].kind == QuizEvent::Kind::stroke_missed);
  CHECK(events[0].backwards);
  CHECK(events[0].refusal == StrokeRefusal::backwards);
  CHECK(strict.quiz.current_stroke() == 0);

  QuizOptions lenient;
  lenient.accept_backwards = true;
  Writer accepting{QuizSession(shi, lenient)};
  const auto accepted = accepting.write(stroke_points(shi.strokes[0], Vec2::Zero(), true));
  REQUIRE_FALSE(accepted.empty());
  CHECK(accepted[0].kind == QuizEvent::Kind::stroke_accepted);
  CHECK(accepted[0].backwards);
  CHECK(accepted[0].refusal == StrokeRefusal::none);
}

TEST_CASE("quiz acceptance decides a stroke written off its place", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  // Shifted across the stroke by 4 mm: within the start neighbourhood (5 mm) and the corridor (6.5 mm),
  // beyond the default mean deviation (3 mm, capped at 3.2 mm), within a mean deviation of 5 mm.
  const Vec2 shift(0.0, 0.004);
  Writer strict_writer{QuizSession(shi)};
  const auto refused = strict_writer.write(stroke_points(shi.strokes[0], shift));
  REQUIRE(refused.size() == 1);
  CHECK(refused[0].kind == QuizEvent::Kind::stroke_missed);
  CHECK(refused[0].refusal == StrokeRefusal::wrong_place);
  CHECK_FALSE(refused[0].written_stroke);
  QuizOptions lenient;
  lenient.acceptance.mean_deviation_m = 0.005;
  lenient.acceptance.mean_deviation_cap_m = 0.005;
  Writer lenient_writer{QuizSession(shi, lenient)};
  CHECK(has(lenient_writer.write(stroke_points(shi.strokes[0], shift)), QuizEvent::Kind::stroke_accepted));
  // A start neighbourhood smaller than the shift: never entered, so in the wrong place whatever the rest.
  lenient.start_radius_m = 0.003;
  Writer small_start{QuizSession(shi, lenient)};
  const auto outside = small_start.write(stroke_points(shi.strokes[0], shift));
  REQUIRE(outside.size() == 1);
  CHECK(outside[0].refusal == StrokeRefusal::wrong_place);
}

TEST_CASE("quiz neither accepts nor counts a touch too short to judge", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  Writer writer{QuizSession(shi)};
  const Vec2 start = shi.strokes[0].start();
  const auto events = writer.write({start, start + Vec2(1e-4, 0.0)});
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == QuizEvent::Kind::too_short);
  CHECK(writer.quiz.total_misses() == 0);
  CHECK(writer.quiz.current_stroke() == 0);
}

TEST_CASE("quiz judges a run still open when the input ends", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  QuizSession quiz(shi);
  double t = 0.0;
  for (const Vec2& p : stroke_points(shi.strokes[0])) {
    quiz.feed({t, p, true});
    t += 1e-3;
  }
  const auto events = quiz.finish();
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == QuizEvent::Kind::stroke_accepted);
  CHECK(quiz.events().size() == 1);
}

TEST_CASE("quiz refuses samples going back in time or not finite, naming the sample", "[analysis][quiz]") {
  const PlacedCharacter& shi = character_of(U'十');
  QuizSession quiz(shi);
  quiz.feed({1.0, Vec2::Zero(), false});
  CHECK_THROWS_WITH(quiz.feed({0.5, Vec2::Zero(), false}), Catch::Contains("sample 1"));
  CHECK_THROWS_AS(quiz.feed({2.0, Vec2(std::nan(""), 0.0), true}), InvalidArgument);
  QuizOptions bad;
  bad.acceptance.corridor_m = 0.0;
  CHECK_THROWS_WITH(QuizSession(shi, bad), Catch::Contains("corridor_m"));
  bad = QuizOptions{};
  bad.start_radius_m = -1.0;
  CHECK_THROWS_WITH(QuizSession(shi, bad), Catch::Contains("start_radius_m"));
  PlacedCharacter empty = shi;
  empty.strokes.clear();
  CHECK_THROWS_AS(QuizSession(empty), InvalidArgument);
}
