// The trainer's words for a learner and the demonstration's timing (src/trainer/learner_text.hpp,
// demonstration.hpp): pure functions, tested without a window; and the trial's view (trial_view.hpp), which
// turns the display channel's events into those words.
#include "trainer/learner_text.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "embedded_scenes.hpp"
#include "trainer/demonstration.hpp"
#include "trainer/trial_view.hpp"

using namespace calligraphy;
using namespace calligraphy::trainer;

namespace {
bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}
}  // namespace

TEST_CASE("the device line says what to do with the device in use and never 'guidance on' unfelt") {
  CHECK(learner_device("mouse", false, false) == LearnerDevice::mouse);
  CHECK(learner_device("mouse-hand", false, false) == LearnerDevice::mouse_hand);
  CHECK(learner_device("openhaptics", true, false) == LearnerDevice::haptic);
  CHECK(learner_device("simulated", false, true) == LearnerDevice::simulated_writer);
  CHECK(learner_device("emulated-phantom", false, false) == LearnerDevice::simulated_device);
  CHECK(device_line(LearnerDevice::mouse, true) ==
        "Hold the left mouse button and draw each stroke; a mouse cannot push back, so nothing is felt.");
  for (const LearnerDevice d : {LearnerDevice::mouse, LearnerDevice::mouse_hand,
                                LearnerDevice::simulated_writer, LearnerDevice::simulated_device}) {
    for (const bool guidance : {true, false}) {
      const std::string line = device_line(d, guidance);
      CHECK_FALSE(contains(line, "guidance on"));
      CHECK_FALSE(contains(line, "guides"));
    }
  }
  CHECK(contains(device_line(LearnerDevice::haptic, true), "Press the pen to the paper"));
  CHECK(contains(device_line(LearnerDevice::haptic, true), "guides your hand"));
  CHECK_FALSE(contains(device_line(LearnerDevice::haptic, false), "guides your hand"));
  CHECK(contains(device_line(LearnerDevice::mouse_hand, true), "nothing is felt"));
}

TEST_CASE("stroke k of n is 1-based and ends with every stroke written") {
  CHECK(stroke_of(1, 5) == "Stroke 1 of 5");
  CHECK(stroke_of(5, 5) == "Stroke 5 of 5");
  CHECK(stroke_of(6, 5) == "Every stroke written");
}

TEST_CASE("an offset is named in millimetres and the paper's directions") {
  CHECK(offset_words(Vec2(-0.003, 0.0)) == "3 mm left");
  CHECK(offset_words(Vec2(0.0042, 0.0)) == "4 mm right");
  CHECK(offset_words(Vec2(0.0, 0.0025)) == "2 mm above");  // y away from the writer: up on the screen
  CHECK(offset_words(Vec2(0.0, -0.0012)) == "1.2 mm below");
  CHECK(offset_words(Vec2(-0.002, 0.004)) == "2 mm left and 4 mm above");
  CHECK(offset_words(Vec2(-0.006, 0.0004)) == "6 mm left");  // the small part is left out
}

TEST_CASE("a written stroke says how far off it was on average") {
  const StrokeAcceptance acceptance;  // mean deviation limit 3 mm: good at 1.5 mm or less
  const Feedback good = stroke_written(2, 0.0012, acceptance);
  CHECK(good.text == "Stroke 2: good, 1.2 mm off on average");
  CHECK(good.tone == FeedbackTone::good);
  const Feedback off = stroke_written(3, 0.0024, acceptance);
  CHECK(off.text == "Stroke 3: written, 2.4 mm off on average; keep to the middle of the stroke");
  CHECK(off.tone == FeedbackTone::fix);
  CHECK(stroke_written(1, std::nan(""), acceptance).text == "Stroke 1: written");
}

TEST_CASE("each refusal reads in the learner's terms") {
  RefusedAttempt a;
  a.stroke_1based = 4;
  a.refusal = StrokeRefusal::too_short;
  CHECK(stroke_refused(a).text == "Stroke 4: too short; carry on to the end");
  a.stroke_1based = 3;
  a.refusal = StrokeRefusal::backwards;
  CHECK(stroke_refused(a).text == "Stroke 3: written backwards; start at the other end");
  a.refusal = StrokeRefusal::wrong_place;
  a.start_offset_m = Vec2(-0.003, -0.008);
  a.start_radius_m = 0.005;
  CHECK(stroke_refused(a).text == "Stroke 3: started 3 mm left and 8 mm below the start");
  a.start_offset_m = Vec2(-0.0065, 0.0);
  CHECK(stroke_refused(a).text == "Stroke 3: started 6 mm left of the start");
  a.start_offset_m = Vec2(0.001, 0.0);  // started within the start neighbourhood: the path was off
  CHECK(stroke_refused(a).text == "Stroke 3: off the stroke; follow the outline");
  a.start_offset_m.reset();
  CHECK(stroke_refused(a).text == "Stroke 3: off the stroke; follow the outline");
  a.stroke_1based = 4;
  a.refusal = StrokeRefusal::wrong_order;
  a.written_instead_1based = 5;
  CHECK(stroke_refused(a).text == "That was stroke 5; stroke 4 comes first");
  a.written_instead_1based.reset();
  CHECK(stroke_refused(a).text == "Stroke 4 comes first: that stroke comes later");
  a.refusal = StrokeRefusal::wrong_stroke;
  a.written_instead_1based = 2;
  CHECK(stroke_refused(a).text == "That was stroke 2; now write stroke 4");
  CHECK(stroke_refused(a).tone == FeedbackTone::fix);
}

TEST_CASE("a hint and an assisted stroke are said with their 1-based number") {
  CHECK(stroke_hint(3).text == "Here is stroke 3: follow the blue path from its start");
  CHECK(stroke_hint(3).tone == FeedbackTone::hint);
  CHECK(stroke_assisted(2).text == "Stroke 2 shown and counted as assisted");
}

TEST_CASE("the demonstration draws each stroke at the pace, in order, with a pause before each") {
  const DemoPace pace{0.08, 0.5};
  const DemoSchedule schedule({0.04, 0.008, 0.0}, pace);  // 40 mm, 8 mm (a dot), an empty stroke
  REQUIRE(schedule.strokes() == 3);
  CHECK(schedule.stroke_duration_s(0) == Approx(0.5));          // 40 mm at 80 mm/s
  CHECK(schedule.stroke_duration_s(1) == Approx(kMinStrokeS));  // 0.1 s at the pace: the least time instead
  CHECK(schedule.stroke_duration_s(2) == Approx(kMinStrokeS));
  CHECK(schedule.duration_s() == Approx(3 * 0.5 + 0.5 + 2 * kMinStrokeS));
  CHECK(schedule.at(0.2).stroke == 0);
  CHECK(schedule.at(0.2).fraction == 0.0);  // the pause before the first stroke
  CHECK(schedule.at(0.75).stroke == 0);
  CHECK(schedule.at(0.75).fraction == Approx(0.5));  // half-time of a minimum-jerk motion: half the way
  CHECK(schedule.at(1.2).stroke == 1);
  CHECK(schedule.at(1.2).fraction == 0.0);
  const DemoFrame end = schedule.at(schedule.duration_s() + 0.01);
  CHECK(end.done);
  CHECK(end.stroke == 3);
  // The way drawn never goes back within a stroke.
  double last = 0.0;
  for (double t = 0.5; t < 1.0; t += 0.01) {
    const double f = schedule.at(t).fraction;
    CHECK(f >= last);
    last = f;
  }
}

TEST_CASE("minimum jerk and the head of a polyline") {
  CHECK(minimum_jerk(0.0) == 0.0);
  CHECK(minimum_jerk(1.0) == Approx(1.0));
  CHECK(minimum_jerk(2.0) == Approx(1.0));
  const std::vector<Vec2> line{Vec2(0, 0), Vec2(3, 0), Vec2(3, 4)};
  CHECK(polyline_length(line) == Approx(7.0));
  const std::vector<Vec2> half = polyline_head(line, 0.5);  // 3.5 of 7: past the corner by 0.5
  REQUIRE(half.size() == 3);
  CHECK(half.back().x() == Approx(3.0));
  CHECK(half.back().y() == Approx(0.5));
  CHECK(polyline_head(line, 0.0).size() == 1);
  CHECK(polyline_head(line, 1.0).size() == 3);
  CHECK(polyline_head({}, 0.5).empty());
}

TEST_CASE("a start above or below reads without 'of'") {
  RefusedAttempt a;
  a.stroke_1based = 2;
  a.refusal = StrokeRefusal::wrong_place;
  a.start_offset_m = Vec2(0.0, 0.007);
  CHECK(stroke_refused(a).text == "Stroke 2: started 7 mm above the start");
  a.start_offset_m = Vec2(0.009, 0.0);
  CHECK(stroke_refused(a).text == "Stroke 2: started 9 mm right of the start");
}

TEST_CASE("the engineer's guidance words say 'guidance on' only on a haptic device") {
  CHECK(guidance_words(LearnerDevice::haptic, true) == "guidance on");
  CHECK(guidance_words(LearnerDevice::mouse, true) == "no force output: guidance not felt");
  CHECK(guidance_words(LearnerDevice::mouse_hand, true) == "guidance on the simulated pen, not felt");
  CHECK(guidance_words(LearnerDevice::simulated_writer, true) == "guidance on the simulated writer's pen");
  for (const LearnerDevice d : {LearnerDevice::mouse, LearnerDevice::mouse_hand, LearnerDevice::haptic,
                                LearnerDevice::simulated_writer, LearnerDevice::simulated_device})
    CHECK(guidance_words(d, false) == "guidance off");
}

// ---- The trial's view turns the display channel's events into the learner's lines (trial_view.cpp).

namespace {
TracePoint trace_point(std::uint64_t tick, const Vec2& at_m, InteractionState state) {
  TracePoint p;
  p.tick = tick;
  p.hip_m = DisplayPoint3{at_m.x(), at_m.y(), state == InteractionState::separation ? 0.005 : -0.001};
  p.state = state;
  return p;
}
}  // namespace

TEST_CASE("a refused attempt's line names where it started against the stroke's start") {
  const Scene& scene = calligraphy::testing::embedded_scene(U'十');
  DisplayChannel channel;
  TrialView view;
  view.scene = &scene;
  const std::vector<int> ids = typical_ids_of(CharacterLibrary::embedded().load(U'十'));
  const PlacedStroke& first = scene.characters[0].strokes[0];
  // The pen lands 6 mm left of stroke 1's start and 1 mm above, comes to the start and writes a little.
  const Vec2 landing = first.start() + Vec2(-0.006, 0.001);
  std::uint64_t tick = 1;
  channel.push_trace(trace_point(tick++, landing, InteractionState::adjusting));
  channel.push_trace(trace_point(tick++, first.start(), InteractionState::writing));
  channel.push_trace(trace_point(tick++, first.start() + Vec2(0.002, 0.0), InteractionState::writing));
  channel.push_trace(trace_point(tick, first.start() + Vec2(0.002, 0.0), InteractionState::separation));
  DisplayEvent abandoned;
  abandoned.kind = DisplayEventKind::stroke_abandoned;
  abandoned.tick = tick;
  abandoned.refusal = StrokeRefusal::wrong_place;
  channel.push_event(abandoned);
  view.consume(channel, ids);
  REQUIRE(view.feedback);
  CHECK(view.feedback->text == "Stroke 1: started 6 mm left of the start");
  CHECK(view.feedback->tone == FeedbackTone::fix);

  DisplayEvent written;
  written.kind = DisplayEventKind::stroke_completed;
  written.tick = ++tick;
  written.mean_deviation_m = 0.0004;
  channel.push_event(written);
  view.consume(channel, ids);
  CHECK(view.feedback->text == "Stroke 1: good, 0.4 mm off on average");

  DisplaySnapshot hinted;
  hinted.tick = ++tick;
  hinted.stroke = 1;
  hinted.stroke_index = 1;
  hinted.strokes_total = 2;
  hinted.misses = 3;
  hinted.hint_shown = true;
  channel.publish(hinted);
  view.consume(channel, ids);
  CHECK(view.feedback->text == "Here is stroke 2: follow the blue path from its start");
  REQUIRE(view.hint);
  CHECK(view.hint->stroke == 1);

  DisplayEvent assisted;
  assisted.kind = DisplayEventKind::stroke_assisted;
  assisted.tick = ++tick;
  assisted.stroke = 1;
  assisted.stroke_index = 1;
  channel.push_event(assisted);
  view.consume(channel, ids);
  CHECK(view.feedback->text == "Stroke 2 shown and counted as assisted");
  REQUIRE(view.assisted);
  CHECK(view.assisted->stroke == 1);
}

TEST_CASE("the miss that brings a hint is said before the hint, which stays the last line") {
  const Scene& scene = calligraphy::testing::embedded_scene(U'十');
  DisplayChannel channel;
  TrialView view;
  view.scene = &scene;
  const std::vector<int> ids = typical_ids_of(CharacterLibrary::embedded().load(U'十'));
  const PlacedStroke& first = scene.characters[0].strokes[0];
  channel.push_trace(trace_point(1, first.start(), InteractionState::writing));
  channel.push_trace(trace_point(2, first.start() + Vec2(0.003, 0.0), InteractionState::writing));
  channel.push_trace(trace_point(3, first.start() + Vec2(0.003, 0.0), InteractionState::separation));
  DisplayEvent abandoned;
  abandoned.kind = DisplayEventKind::stroke_abandoned;
  abandoned.tick = 3;
  abandoned.refusal = StrokeRefusal::too_short;
  channel.push_event(abandoned);
  DisplaySnapshot hinted;
  hinted.tick = 3;
  hinted.strokes_total = 2;
  hinted.misses = 1;
  hinted.hint_shown = true;
  channel.publish(hinted);
  view.consume(channel, ids);
  REQUIRE(view.feedback);
  CHECK(view.feedback->text == "Here is stroke 1: follow the blue path from its start");
  CHECK(view.refused);         // the refused attempt is still drawn, greyed
  view.consume(channel, ids);  // the same hint again: said once
  CHECK(view.feedback->text == "Here is stroke 1: follow the blue path from its start");
}
