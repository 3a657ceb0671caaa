// The simulated writer's closed loop (docs/writer.md): it sees its pen only after the visuomotor delay,
// corrects towards the reference, paces itself by the error it sees (steering law), moves in
// minimum-jerk segments, and is deterministic for a seed.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <vector>

#include "writer_test_harness.hpp"

using namespace calligraphy;
using namespace calligraphy::testing;

namespace {

WriterProfile unbiased_novice() {
  WriterProfile p = WriterProfile::novice();
  p.bias_offset_m = 0.0;
  p.scale_error = 0.0;
  p.stroke_jitter_m = 0.0;
  p.mid_stroke_lift_probability = 0.0;
  p.outside_touch_probability = 0.0;
  p.hesitation_probability = 0.0;
  return p;
}

constexpr double kStep_s = 1e-3;

// Drives `writer` open-loop for `seconds`: each millisecond it is shown the pen where `pen_at` puts
// it (given the writer's own target), and a display that never changes (it never takes the stroke, so
// each attempt written whole ends `not_accepted`); returns its targets.
std::vector<Vec3> drive(SimulatedWriter& writer, double seconds,
                        const std::function<Vec3(double, const Vec3&)>& pen_at) {
  std::vector<Vec3> targets;
  const auto ticks = static_cast<int>(std::lround(seconds / kStep_s));
  for (int k = 0; k < ticks; ++k) {
    const double t = k * kStep_s;
    DeviceState pen;
    pen.time_s = t;
    pen.position_m = pen_at(t, writer.target(t));
    writer.observe(RenderOutput{}, pen);
    targets.push_back(writer.target(t));
  }
  return targets;
}

}  // namespace

TEST_CASE("The writer corrects a displaced pen only after its visuomotor delay", "[writer]") {
  const Scene scene = horizontal_stroke_scene();
  const WriterProfile profile = unbiased_novice();
  SimulatedWriter probe(scene, profile, 5);
  drive(probe, 4.0, [](double, const Vec3& target) { return target; });
  REQUIRE(!probe.log().attempts.empty());
  const double touch_down = probe.log().attempts.front().touch_down_s;
  REQUIRE(touch_down > 0.0);
  const double displaced_from = touch_down + 0.4;  // well into the stroke
  const Vec3 offset(0.0, 0.003, 0.0);              // 3 mm across the stroke

  SimulatedWriter tracked(scene, profile, 5);
  SimulatedWriter displaced(scene, profile, 5);
  const std::vector<Vec3> a = drive(tracked, displaced_from + 1.0, [](double, const Vec3& x) { return x; });
  const std::vector<Vec3> b = drive(displaced, displaced_from + 1.0, [&](double t, const Vec3& x) {
    return t >= displaced_from ? Vec3(x + offset) : x;
  });
  double first_difference = -1.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if ((a[k] - b[k]).norm() > 1e-9) {
      first_difference = static_cast<double>(k) * kStep_s;
      break;
    }
  }
  INFO("displaced at " << displaced_from << " s, targets differ from " << first_difference << " s");
  REQUIRE(first_difference > 0.0);
  CHECK(first_difference >= displaced_from + profile.visual_delay_s - 1e-9);
  CHECK(first_difference <= displaced_from + profile.visual_delay_s + profile.vision_period_s + 2 * kStep_s);
  // The correction is towards the reference: against the offset.
  const std::size_t late = a.size() - 1;
  CHECK(b[late].y() < a[late].y() - 5e-4);
}

TEST_CASE("A pen held on the stroke is written faster than one the writer sees off it (steering law)",
          "[writer]") {
  const Scene scene = horizontal_stroke_scene();
  WriterProfile profile = unbiased_novice();
  profile.bias_offset_m = 0.0025;  // its copy lies 2.5 mm off the reference
  const double stroke_y = scene.characters[0].strokes[0].start().y();
  SimulatedWriter held(scene, profile, 9);
  SimulatedWriter free(scene, profile, 9);
  // Held: a perfect fixture keeps the pen on the stroke's line whatever the hand aims at.
  drive(held, 6.0, [&](double, const Vec3& x) { return Vec3(x.x(), stroke_y, x.z()); });
  drive(free, 6.0, [](double, const Vec3& x) { return x; });
  REQUIRE(!held.log().attempts.empty());
  REQUIRE(!free.log().attempts.empty());
  const WriterAttempt& h = held.log().attempts.front();
  const WriterAttempt& f = free.log().attempts.front();
  REQUIRE(h.end == AttemptEnd::not_accepted);
  REQUIRE(f.end == AttemptEnd::not_accepted);
  INFO("held " << h.end_s - h.touch_down_s << " s, free " << f.end_s - f.touch_down_s << " s");
  CHECK(h.end_s - h.touch_down_s < 0.9 * (f.end_s - f.touch_down_s));
}

TEST_CASE("The hand's target moves in minimum-jerk segments: at rest at both ends of a stroke", "[writer]") {
  const Scene scene = horizontal_stroke_scene();
  SimulatedWriter writer(scene, unbiased_novice(), 2);
  const std::vector<Vec3> x = drive(writer, 6.0, [](double, const Vec3& target) { return target; });
  const WriterAttempt& a = writer.log().attempts.front();
  REQUIRE(a.end == AttemptEnd::not_accepted);
  const auto begin = static_cast<std::size_t>(std::lround(a.touch_down_s / kStep_s)) + 1;
  // The writing ends where the lift begins: the target's z starts to rise.
  std::size_t end = begin;
  while (end + 1 < x.size() && x[end + 1].z() <= x[begin].z() + 1e-7) ++end;
  REQUIRE(end > begin + 100);
  std::vector<double> speed;
  for (std::size_t k = begin; k < end; ++k) speed.push_back((x[k + 1] - x[k]).head<2>().norm() / kStep_s);
  const auto peak = std::max_element(speed.begin(), speed.end());
  const double peak_share = static_cast<double>(peak - speed.begin()) / static_cast<double>(speed.size());
  INFO("peak " << *peak << " m/s at " << peak_share << " of the stroke; ends " << speed.front() << ", "
               << speed.back() << " m/s");
  CHECK(speed.front() < 0.05 * *peak);
  CHECK(speed.back() < 0.05 * *peak);
  CHECK(peak_share > 0.3);
  CHECK(peak_share < 0.7);
}

TEST_CASE("A writer's trial is deterministic for a seed and differs across seeds", "[writer]") {
  const Scene scene = scene_of(U'口');
  WriterTrialOptions options;
  options.writer = WriterProfile::foreign();
  options.seed = 3;
  const WriterTrial first = run_writer_trial(scene, options);
  const WriterTrial again = run_writer_trial(scene, options);
  REQUIRE(first.trace.size() == again.trace.size());
  bool same = true;
  for (std::size_t k = 0; k < first.trace.size(); ++k) {
    same = same && first.trace[k].position_m == again.trace[k].position_m &&
           first.trace[k].force_n == again.trace[k].force_n;
  }
  CHECK(same);
  CHECK(first.log.attempts.size() == again.log.attempts.size());
  options.seed = 4;
  const WriterTrial other = run_writer_trial(scene, options);
  CHECK(other.metrics.mean_deviation_m != first.metrics.mean_deviation_m);
}

TEST_CASE("A stroke the display does not take is written again, and one it takes is not", "[writer]") {
  const Scene scene = horizontal_stroke_scene();
  const double paper_z = scene.layout.paper_z_m;
  for (const bool display_takes_it : {false, true}) {
    SimulatedWriter writer(scene, unbiased_novice(), 4);
    bool written = false;  // the display's verdict: the pen wrote on the paper and left it
    bool touched = false;
    for (int k = 0; k < 20000 && !writer.done(); ++k) {
      const double t = k * kStep_s;
      DeviceState pen;
      pen.time_s = t;
      pen.position_m = writer.target(t);
      touched = touched || pen.position_m.z() < paper_z;
      if (display_takes_it && touched && pen.position_m.z() > paper_z) written = true;
      RenderOutput display;
      display.stroke = written ? 1 : 0;
      display.finished = written;
      writer.observe(display, pen);
    }
    const WriterLog& log = writer.log();
    INFO("display takes it: " << display_takes_it);
    REQUIRE(!log.attempts.empty());
    if (display_takes_it) {
      CHECK(log.attempts.size() == 1);
      CHECK(log.attempts.front().end == AttemptEnd::completed);
      CHECK(log.not_accepted == 0);
    } else {
      // Written whole each time, seen not taken, written again until the writer gives up.
      CHECK(log.attempts.size() == static_cast<std::size_t>(unbiased_novice().max_attempts_per_stroke));
      CHECK(log.not_accepted == log.attempts.size());
      CHECK(log.gave_up);
      CHECK(log.strokes_given_up == 1);
    }
  }
}

TEST_CASE("A writer that gives up on a stroke moves on to the next one and writes it", "[writer]") {
  // 十 on a display that never takes a stroke: the first is written `max_attempts_per_stroke` times, then
  // left; the second is written once (the writer no longer looks for the display's verdict) and the writer
  // is done, having written every stroke it meant to.
  const Scene scene = scene_of(U'十');
  const WriterProfile profile = unbiased_novice();
  SimulatedWriter writer(scene, profile, 4);
  for (int k = 0; k < 60000 && !writer.done(); ++k) {
    const double t = k * kStep_s;
    DeviceState pen;
    pen.time_s = t;
    pen.position_m = writer.target(t);
    writer.observe(RenderOutput{}, pen);
  }
  REQUIRE(writer.done());
  const WriterLog& log = writer.log();
  CHECK(log.gave_up);
  CHECK(log.strokes_given_up == 1);
  REQUIRE(log.attempts.size() == static_cast<std::size_t>(profile.max_attempts_per_stroke) + 1);
  for (std::size_t a = 0; a + 1 < log.attempts.size(); ++a) CHECK(log.attempts[a].scene_stroke == 0);
  CHECK(log.attempts.back().scene_stroke == 1);
  CHECK(log.attempts.back().end == AttemptEnd::completed);
}
