// Stroke progress and the stroke matcher (model/stroke_progress.hpp, analysis/stroke_matcher.hpp):
// corners gone round on either side, ends short of or past the end, and the refusals, on strokes laid
// out in a 60 mm box.
#include "calligraphy/model/stroke_progress.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/scene.hpp"

using namespace calligraphy;

namespace {

// 1 mm in data units of a 60 mm box.
constexpr double kMmUnits = 1024.0 / 60.0;

// Stroke 0: a 横折 (right 30 mm, then down 30 mm); stroke 1: a 横 below it; stroke 2: a 6 mm dot.
Scene test_scene() {
  Character c;
  c.code_point = U'口';
  Stroke hz;
  hz.typical_id = 7;
  hz.elements = {StrokeElement::line({200, 700}, {200 + 30 * kMmUnits, 700}),
                 StrokeElement::line({200 + 30 * kMmUnits, 700}, {200 + 30 * kMmUnits, 700 - 30 * kMmUnits})};
  hz.attraction_factors = {1.0, 1.0, 1.0};
  Stroke h;
  h.typical_id = 1;
  h.elements = {StrokeElement::line({200, 100}, {200 + 30 * kMmUnits, 100})};
  h.attraction_factors = {1.0, 1.0};
  Stroke dot;
  dot.typical_id = 4;
  dot.elements = {StrokeElement::line({700, 100}, {700 + 6 * kMmUnits, 100})};
  dot.attraction_factors = {1.0, 1.0};
  c.strokes = {hz, h, dot};
  return Scene::lay_out({c});
}

const double kStartRadius = SceneLayout{}.start_radius_m;

// Points every 0.1 mm along the polyline `corners` [m].
std::vector<Vec2> along(const std::vector<Vec2>& corners) {
  std::vector<Vec2> path{corners.front()};
  for (std::size_t i = 1; i < corners.size(); ++i) {
    const Vec2 step = corners[i] - corners[i - 1];
    const int n = std::max(1, static_cast<int>(std::ceil(step.norm() / 1e-4)));
    for (int k = 1; k <= n; ++k) path.push_back(corners[i - 1] + step * (static_cast<double>(k) / n));
  }
  return path;
}

Vec2 mm(double x, double y) { return Vec2(x, y) * 1e-3; }

struct Fed {
  bool completed_on_the_way = false;
  std::size_t element_at_plane = 0;  // element index when the tip first crossed the first element's plane
  bool lifted_written = false;
  StrokeRefusal refusal = StrokeRefusal::none;
};

// The path fed to a tracker from its first point (WS entered there), then lifted.
Fed feed(const PlacedStroke& stroke, const std::vector<Vec2>& path) {
  StrokeProgressTracker tracker;
  tracker.begin(stroke, path.front(), StrokeAcceptance{});
  Fed fed;
  for (std::size_t i = 1; i < path.size() && tracker.in_attempt(); ++i) {
    if (tracker.update(path[i])) fed.completed_on_the_way = true;
  }
  fed.refusal = tracker.refusal();
  fed.lifted_written = fed.completed_on_the_way || tracker.lift();
  return fed;
}

}  // namespace

TEST_CASE("A corner counts as gone round when the pen cuts it inside or overshoots it", "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedStroke& hz = scene.characters[0].strokes[0];
  const Vec2 start = hz.start();
  const Vec2 corner = hz.elements[0].end();
  for (const double cut_mm : {0.5, 1.5, 2.5}) {
    INFO("cut inside by " << cut_mm << " mm");
    // Straight from 2 cut-lengths before the corner to 2 cut-lengths below it: the pen never crosses the
    // corner's feature plane x = corner.x.
    const std::vector<Vec2> path =
        along({start, corner - mm(2 * cut_mm, 0), corner + mm(0, -2 * cut_mm), corner + mm(0, -10)});
    StrokeProgressTracker tracker;
    tracker.begin(hz, path.front(), StrokeAcceptance{});
    bool advanced = false;
    for (const Vec2& p : path) {
      CHECK(p.x() <= corner.x() + 1e-12);
      tracker.update(p);
      advanced = advanced || tracker.element_index() == 1;
    }
    CHECK(advanced);
  }
  // Overshoot outside by 2 mm, then down along the vertical.
  const std::vector<Vec2> over =
      along({start, corner + mm(2, 0), corner + mm(2, -1), corner + mm(0, -4), corner + mm(0, -10)});
  StrokeProgressTracker tracker;
  tracker.begin(hz, over.front(), StrokeAcceptance{});
  for (const Vec2& p : over) tracker.update(p);
  CHECK(tracker.element_index() == 1);
}

TEST_CASE("A stroke is written when the pen lifts short of its end or past it, not half way",
          "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedStroke& h = scene.characters[0].strokes[1];
  const Vec2 a = h.start();
  const Vec2 b = h.end();
  for (const double end_mm : {-3.0, -1.0, 0.0, 1.0, 4.0}) {
    INFO("lifted " << end_mm << " mm from the end");
    const Fed fed = feed(h, along({a, b + mm(end_mm, 0)}));
    CHECK(fed.lifted_written);
    CHECK_FALSE(fed.completed_on_the_way);  // completes at the lift
  }
  const Fed half = feed(h, along({a, (a + b) / 2}));
  CHECK_FALSE(half.lifted_written);
  CHECK(half.refusal == StrokeRefusal::too_short);
  // Short by more than the shortfall the stroke's length allows (it grows with the length: 12 mm on this
  // 40 mm stroke, so 8 mm short is written).
  const double allowed_mm = 1e3 * StrokeAcceptance{}.allowed_shortfall_m((b - a).norm());
  CHECK(feed(h, along({a, b - mm(allowed_mm - 1.5, 0)})).lifted_written);
  const Fed too_short = feed(h, along({a, b - mm(allowed_mm + 1.5, 0)}));
  CHECK_FALSE(too_short.lifted_written);
  CHECK(too_short.refusal == StrokeRefusal::too_short);
  // Moved 4 mm across: in the start neighbourhood, but in the wrong place.
  const Fed moved = feed(h, along({a + mm(0, 4), b + mm(0, 4)}));
  CHECK_FALSE(moved.lifted_written);
  CHECK(moved.refusal == StrokeRefusal::wrong_place);
}

TEST_CASE(
    "Past the end the pen may move in the end neighbourhood, and leaving it off the stroke loses the stroke",
    "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedStroke& h = scene.characters[0].strokes[1];
  const Vec2 a = h.start();
  const Vec2 b = h.end();
  // A small loop past the end, then the lift: written.
  CHECK(feed(h, along({a, b + mm(2, 0), b + mm(3, 2), b + mm(1, 1)})).lifted_written);
  // On 12 mm upwards without lifting: another shape.
  const Fed scribble = feed(h, along({a, b + mm(1, 0), b + mm(1, 12)}));
  CHECK_FALSE(scribble.lifted_written);
  CHECK(scribble.refusal == StrokeRefusal::wrong_stroke);
  // Back along the stroke past the neighbourhood: still the stroke, written when it leaves.
  const Fed back = feed(h, along({a, b + mm(1, 0), b - mm(12, 0)}));
  CHECK(back.completed_on_the_way);
}

TEST_CASE("A dot displaced along itself is written, and half a dot is not", "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedStroke& dot = scene.characters[0].strokes[2];
  const Vec2 a = dot.start();
  const Vec2 b = dot.end();
  CHECK(feed(dot, along({a + mm(2, 0), b + mm(2, 0)})).lifted_written);  // 2 mm late, 2 mm past
  CHECK(feed(dot, along({a - mm(2, 0), b - mm(2, 0)})).lifted_written);  // 2 mm early, 2 mm short
  CHECK_FALSE(feed(dot, along({a, (a + b) / 2})).lifted_written);
  CHECK_FALSE(feed(dot, along({(a + b) / 2, b})).lifted_written);
  // Backwards from its end, which lies inside the start neighbourhood of a 6 mm dot.
  const Fed backwards = feed(dot, along({b, a}));
  CHECK_FALSE(backwards.lifted_written);
  CHECK(backwards.refusal == StrokeRefusal::backwards);
}

TEST_CASE("The stroke matcher names why a path does not write the expected stroke", "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedCharacter& c = scene.characters[0];
  const PlacedStroke& hz = c.strokes[0];
  const PlacedStroke& h = c.strokes[1];
  const std::vector<Vec2> hz_path = along({hz.start(), hz.elements[0].end(), hz.end()});
  const std::vector<Vec2> h_path = along({h.start(), h.end()});

  StrokeMatch m = match_stroke(c, 0, hz_path, kStartRadius);
  CHECK(m.accepted);
  CHECK(m.refusal == StrokeRefusal::none);
  CHECK(m.covered_fraction == Approx(1.0).margin(0.02));
  // A sparse path (the corners only) is read as straight lines between its points.
  CHECK(match_stroke(c, 0, std::vector<Vec2>{hz.start(), hz.elements[0].end(), hz.end()}, kStartRadius)
            .accepted);

  m = match_stroke(c, 0, h_path, kStartRadius);
  CHECK_FALSE(m.accepted);
  CHECK(m.refusal == StrokeRefusal::wrong_order);
  CHECK(m.matched_stroke == 1);

  m = match_stroke(c, 1, hz_path, kStartRadius);
  CHECK(m.refusal == StrokeRefusal::wrong_stroke);
  CHECK(m.matched_stroke == 0);

  std::vector<Vec2> reversed(hz_path.rbegin(), hz_path.rend());
  CHECK(match_stroke(c, 0, reversed, kStartRadius).refusal == StrokeRefusal::backwards);

  std::vector<Vec2> far = hz_path;
  for (Vec2& p : far) p += mm(0, 12);
  CHECK(match_stroke(c, 0, far, kStartRadius).refusal == StrokeRefusal::wrong_place);

  const std::vector<Vec2> first_third(hz_path.begin(),
                                      hz_path.begin() + static_cast<long>(hz_path.size() / 3));
  CHECK(match_stroke(c, 0, first_third, kStartRadius).refusal == StrokeRefusal::too_short);
}

TEST_CASE("attempt_stroke is the pairwise test of the matcher: one stroke, no other named",
          "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedCharacter& c = scene.characters[0];
  const PlacedStroke& hz = c.strokes[0];
  const PlacedStroke& h = c.strokes[1];
  const std::vector<Vec2> hz_path = along({hz.start(), hz.elements[0].end(), hz.end()});
  const std::vector<Vec2> h_path = along({h.start(), h.end()});

  const StrokeAttempt own = attempt_stroke(hz, hz_path, kStartRadius);
  CHECK(own.entered);
  CHECK(own.written);
  CHECK(own.refusal == StrokeRefusal::none);
  const StrokeMatch matched = match_stroke(c, 0, hz_path, kStartRadius);
  CHECK(own.covered_fraction == matched.covered_fraction);
  CHECK(own.mean_deviation_m == matched.mean_deviation_m);

  // The 横 tried on the 横折: never within the start radius of its start, so never entered.
  const StrokeAttempt other = attempt_stroke(hz, h_path, kStartRadius);
  CHECK_FALSE(other.entered);
  CHECK_FALSE(other.written);
  CHECK(other.refusal == StrokeRefusal::wrong_place);
  CHECK(other.covered_fraction == 0.0);
  // ... where match_stroke names the stroke it writes.
  CHECK(attempt_stroke(h, h_path, kStartRadius).written);

  // Reversed: refused by the tracker alone as not along the stroke; written when reversed back.
  const std::vector<Vec2> reversed(hz_path.rbegin(), hz_path.rend());
  CHECK_FALSE(attempt_stroke(hz, reversed, kStartRadius).written);
  const std::vector<Vec2> first_third(hz_path.begin(),
                                      hz_path.begin() + static_cast<long>(hz_path.size() / 3));
  const StrokeAttempt short_one = attempt_stroke(hz, first_third, kStartRadius);
  CHECK(short_one.entered);
  CHECK(short_one.refusal == StrokeRefusal::too_short);
  CHECK(short_one.covered_fraction == Approx(1.0 / 3.0).margin(0.03));

  CHECK_THROWS_WITH(attempt_stroke(hz, std::vector<Vec2>{}, kStartRadius),
                    Catch::Contains("attempt_stroke") && Catch::Contains("empty path"));
  CHECK_THROWS_AS(attempt_stroke(hz, hz_path, std::nan("")), InvalidArgument);
  PlacedStroke unplaced = hz;
  unplaced.centre_line = StrokeCentreLine{};
  CHECK_THROWS_WITH(attempt_stroke(unplaced, hz_path, kStartRadius), Catch::Contains("centre line"));
  PlacedCharacter partly = c;
  partly.strokes[2].centre_line = StrokeCentreLine{};
  CHECK_THROWS_WITH(match_stroke(partly, 0, hz_path, kStartRadius), Catch::Contains("stroke 2"));
}

TEST_CASE("Bad input to the stroke matcher is refused naming it", "[stroke_progress]") {
  const Scene scene = test_scene();
  const PlacedCharacter& c = scene.characters[0];
  const std::vector<Vec2> path{c.strokes[0].start(), c.strokes[0].end()};
  CHECK_THROWS_WITH(match_stroke(c, 3, path, kStartRadius), Catch::Contains("stroke 3"));
  CHECK_THROWS_WITH(match_stroke(c, 0, std::vector<Vec2>{}, kStartRadius), Catch::Contains("empty path"));
  std::vector<Vec2> nan = path;
  nan[1].x() = std::nan("");
  CHECK_THROWS_WITH(match_stroke(c, 0, nan, kStartRadius), Catch::Contains("path point 1"));
  CHECK_THROWS_AS(match_stroke(c, 0, path, 0.0), InvalidArgument);
  // A finite step too long to have a finite length (a sample from another world): read, and refused.
  const StrokeMatch wild =
      match_stroke(c, 0, std::vector<Vec2>{c.strokes[0].start(), Vec2(1e300, -1e300)}, kStartRadius);
  CHECK_FALSE(wild.accepted);
  StrokeAcceptance bad;
  bad.corridor_m = -1.0;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("corridor_m"));
  bad = StrokeAcceptance{};
  bad.shortfall_fraction = 1.0;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("shortfall_fraction"));
  bad = StrokeAcceptance{};
  bad.max_gain_ratio = 0.5;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("max_gain_ratio"));
}

TEST_CASE("Either end of a short stroke may be left unwritten by the end-point scatter, but not half of it",
          "[stroke_progress]") {
  // A 10 mm stroke: the shortfall allowed is 3.5 mm (0.35 of it); the end gap's floor lets either end be
  // 4 mm unwritten (0.4 of it, under the 4.5 mm floor), as another hand's short strokes end.
  Character c;
  c.code_point = U'丶';
  Stroke s;
  s.typical_id = 1;
  s.elements = {StrokeElement::line({400, 500}, {400 + 10 * kMmUnits, 500})};
  s.attraction_factors = {1.0, 1.0};
  c.strokes = {s};
  const Scene scene = Scene::lay_out({c});
  const PlacedStroke& stroke = scene.characters[0].strokes[0];
  const Vec2 a = stroke.start();
  const Vec2 b = stroke.end();
  StrokeAcceptance version_4;
  version_4.use_version_4_end_gaps();
  const StrokeAcceptance now;
  REQUIRE(now.allowed_end_gap_m(0.010) == Approx(0.004));
  REQUIRE(version_4.allowed_end_gap_m(0.010) == Approx(0.0035));
  // Begun 1 mm before the start, lifted 3.8 mm short of the end: 7.2 mm along, 6.5 needed.
  const std::vector<Vec2> end_short = along({a - mm(1, 0), b - mm(3.8, 0)});
  CHECK(attempt_stroke(stroke, end_short, kStartRadius, now).written);
  const StrokeAttempt refused_before = attempt_stroke(stroke, end_short, kStartRadius, version_4);
  CHECK_FALSE(refused_before.written);
  CHECK(refused_before.refusal == StrokeRefusal::too_short);
  // Begun 3.8 mm in, carried 1 mm past the end.
  const std::vector<Vec2> start_late = along({a + mm(3.8, 0), b + mm(1, 0)});
  CHECK(attempt_stroke(stroke, start_late, kStartRadius, now).written);
  CHECK_FALSE(attempt_stroke(stroke, start_late, kStartRadius, version_4).written);
  // Either half, and 4.5 mm short at one end: refused with the floor too.
  for (const std::vector<Vec2>& wrong :
       {along({a, (a + b) / 2}), along({(a + b) / 2, b}), along({a - mm(1, 0), b - mm(4.5, 0)})}) {
    CHECK_FALSE(attempt_stroke(stroke, wrong, kStartRadius, now).written);
  }
}
