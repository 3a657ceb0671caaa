// An application's hostile round against the library's model, analysis and study API: the cases were written
// from the public headers (include/calligraphy/{core,model,collision,render,analysis,trial,study,report}) and
// docs/architecture.md, nearest-point.md, force-rendering.md, metrics.md, stroke-acceptance.md and
// typical-strokes.md before the implementation was read. Every documented precondition and range is tried at
// and past its edge (NaN, infinities, -0, denormals, 1e308, empty containers, one-point strokes, zero-length
// elements, duplicate points, characters of no and of many strokes, indices past the end, sizes of 0); value
// types are copied, moved from and compared; free functions get aliased arguments; the nearest point, the
// force laws and the safety chain are held to their documented properties on random inputs; the matcher gets
// the median reversed, one point, a million points and NaN; Frechet and DTW are held to a brute force written
// here; the study's readers and planners get empty studies, one subject and a constant outcome. A documented
// error must come as documented (its type, a message naming the thing); where a header says nothing, the
// rule is no crash, no hang and no silent wrong result.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/collision/active_stroke.hpp"
#include "calligraphy/collision/constraint_space.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "calligraphy/core/geometry.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/element.hpp"
#include "calligraphy/model/fitting.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "calligraphy/model/polyline.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/render/guidance_schedule.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/render/teacher_replay.hpp"
#include "calligraphy/render/timing_target.hpp"
#include "calligraphy/report/model_report.hpp"
#include "calligraphy/report/model_svg.hpp"
#include "calligraphy/report/score_report.hpp"
#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/study/cohort.hpp"
#include "calligraphy/study/curriculum.hpp"
#include "calligraphy/study/guidance_share.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "calligraphy/study/transfer_set.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "special_values.hpp"
#include "temp_folder.hpp"

namespace {

using namespace calligraphy;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

using calligraphy::testing::kDenormal;
using calligraphy::testing::kInf;
using calligraphy::testing::kNaN;

// What `f` threw: "[thrown] MESSAGE" for an E, "[another exception] ..." for any other exception, "[nothing
// thrown]" otherwise, so that a check names what came instead.
template <typename E, typename F>
std::string thrown(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return std::string("[thrown] ") + e.what();
  } catch (const std::exception& e) {
    return std::string("[another exception] ") + e.what();
  }
  return "[nothing thrown]";
}

// Refused with exception type T and a message holding `text` (case-insensitive).
#define CHECK_REFUSED(T, expr, text)                      \
  CHECK_THAT(thrown<T>([&] { static_cast<void>(expr); }), \
             StartsWith("[thrown]") && Contains(std::string(text), Catch::CaseSensitive::No))

const Character& embedded_character(char32_t code_point) {
  static std::map<char32_t, Character> loaded;
  auto found = loaded.find(code_point);
  if (found == loaded.end())
    found = loaded.emplace(code_point, CharacterLibrary::embedded().load(code_point)).first;
  return found->second;
}

// Scenes kept for the whole run (a renderer holds a pointer to its scene).
const Scene& scene_of(char32_t code_point) {
  static std::map<char32_t, Scene> scenes;
  auto found = scenes.find(code_point);
  if (found == scenes.end())
    found = scenes.emplace(code_point, Scene::lay_out({embedded_character(code_point)})).first;
  return found->second;
}

DeviceInfo desktop_device() {
  DeviceInfo info;
  info.model = "test desktop";
  info.manufacturer = "test";
  info.max_force_n = 7.9;
  info.max_continuous_force_n = 1.75;
  info.max_stiffness_n_per_m = 1000.0;
  info.max_damping_n_s_per_m = 20.0;
  info.intrinsic_damping_n_s_per_m = 0.5;
  info.workspace_radius_m = 0.08;
  info.workspace_size_m = Vec3(0.16, 0.12, 0.07);
  return info;
}

StrokeElement element_of(const std::vector<Vec2>& points) {
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

std::vector<Vec2> reversed(std::vector<Vec2> points) {
  std::reverse(points.begin(), points.end());
  return points;
}

// Pen samples of a path written at 1 kHz from t0, pen down.
std::vector<PenSample> pen_down_samples(const std::vector<Vec2>& path, double t0 = 0.0,
                                        double step_s = 1e-3) {
  std::vector<PenSample> samples;
  for (std::size_t i = 0; i < path.size(); ++i)
    samples.push_back({t0 + static_cast<double>(i) * step_s, path[i], true});
  return samples;
}

// The path densely: points every `step_m` along the polyline.
std::vector<Vec2> densely(const std::vector<Vec2>& polyline, double step_m) {
  return resample(polyline, step_m);
}

}  // namespace

// ---- core
// ---------------------------------------------------------------------------------------------------

TEST_CASE("unseen12j: segment helpers on a zero-length, a denormal, a -0 and a 1e150 segment",
          "[unseen12j]") {
  const Vec2 p(0.3, 0.4);
  CHECK(segment_parameter(Vec2(1, 1), Vec2(1, 1), p) == 0.0);
  CHECK(distance_to_segment(Vec2(1, 1), Vec2(1, 1), p) == Approx((p - Vec2(1, 1)).norm()));
  // A segment whose squared length underflows to zero is a zero-length segment: t = 0, never NaN.
  CHECK(segment_parameter(Vec2::Zero(), Vec2(kDenormal, 0.0), p) == 0.0);
  CHECK(std::isfinite(distance_to_segment(Vec2::Zero(), Vec2(kDenormal, kDenormal), p)));
  CHECK(segment_parameter(Vec2(-0.0, -0.0), Vec2(1.0, 0.0), Vec2(0.5, 1.0)) == 0.5);
  // A segment of 2e150 is within the documented magnitudes: the projection is exact at the middle.
  CHECK(segment_parameter(Vec2(-1e150, 0.0), Vec2(1e150, 0.0), Vec2(0.0, 1e150)) == 0.5);
  CHECK(distance_to_segment(Vec2(-1e150, 0.0), Vec2(1e150, 0.0), Vec2(0.0, 1e150)) == Approx(1e150));
  // The same through nearest_point_on_segment, the servo path's form.
  const NearestPoint np = nearest_point_on_segment(Vec2(2, 2), Vec2(2, 2), p);
  CHECK(np.t == 0.0);
  CHECK(np.foot == Vec2(2, 2));
  CHECK(np.distance == Approx((p - Vec2(2, 2)).norm()));
}

TEST_CASE(
    "unseen12j: force clamps zero a NaN, an infinity and a non-positive cap and scale 1e308 N, never zeroing "
    "it",
    "[unseen12j]") {
  for (const Vec3& bad : {Vec3(kNaN, 0, 0), Vec3(0, kInf, 0), Vec3(0, 0, -kInf)}) {
    CHECK(clamp_force(bad, 3.0) == Vec3::Zero());
    CHECK(clamp_force_magnitude(bad, 3.0) == Vec3::Zero());
  }
  const Vec3 huge(1e308, 1e308, -1e308);
  for (const Vec3& out : {clamp_force(huge, 3.0), clamp_force_magnitude(huge, 3.0)}) {
    REQUIRE(out.allFinite());
    CHECK(out.norm() == Approx(3.0));
    CHECK(out.normalized().isApprox(Vec3(1, 1, -1).normalized(), 1e-12));
  }
  CHECK(clamp_force(Vec3(1, 2, 2), 10.0) == Vec3(1, 2, 2));  // within the cap: unchanged
  CHECK(clamp_force_magnitude(Vec3(1, 0, 0), 0.0) == Vec3::Zero());
  CHECK(clamp_force_magnitude(Vec3(1, 0, 0), -1.0) == Vec3::Zero());
  CHECK(clamp_force_magnitude(Vec3(1, 0, 0), kNaN) == Vec3::Zero());
  // clamp_force with a cap of 0: at most 0 N.
  CHECK(clamp_force(Vec3(1, 0, 0), 0.0).norm() == 0.0);
  // A denormal force is finite and tiny: kept.
  CHECK(clamp_force_magnitude(Vec3(kDenormal, 0, 0), 1.0) == Vec3(kDenormal, 0, 0));
}

TEST_CASE(
    "unseen12j: decimal numbers and UTF-8 at their edges: subnormals kept, -0 round-trips, 1e999 and bad "
    "bytes refused",
    "[unseen12j]") {
  CHECK(parse_finite_double("1e-310") == Approx(1e-310).margin(0));
  CHECK(*parse_finite_double("1e-310") > 0.0);
  REQUIRE(parse_finite_double("-0").has_value());
  CHECK(std::signbit(*parse_finite_double("-0")));
  for (const char* bad : {"", "1e999", "-1e999", "nan", "inf", "-inf", "1.5 ", " 1.5", "1.5x", "0x10"})
    CHECK_FALSE(parse_finite_double(bad).has_value());
  for (const double value : {-0.0, kDenormal, 1e308, -1e308, 0.1, std::nextafter(1.0, 2.0)}) {
    const auto back = parse_finite_double(shortest_decimal(value));
    REQUIRE(back.has_value());
    CHECK(*back == value);
    CHECK(std::signbit(*back) == std::signbit(value));
  }
  CHECK_REFUSED(InvalidArgument, decode_utf8("ab\xff"), "2");  // names the byte offset
  CHECK_REFUSED(InvalidArgument, encode_utf8(char32_t{0xD800}), "");
  CHECK_REFUSED(InvalidArgument, encode_utf8(char32_t{0x110000}), "");
  CHECK(describe_character(U'永') == "永 (U+6C38)");
}

// ---- model
// --------------------------------------------------------------------------------------------------

TEST_CASE(
    "unseen12j: stroke elements refuse non-finite control points naming the index and counts outside 3..5",
    "[unseen12j]") {
  CHECK_REFUSED(InvalidArgument, StrokeElement::line(Vec2(kNaN, 0), Vec2(1, 1)),
                "control point 0 is not finite");
  CHECK_REFUSED(InvalidArgument, StrokeElement::line(Vec2(0, 0), Vec2(1, kInf)),
                "control point 1 is not finite");
  const Vec2 curve[5] = {Vec2(0, 0), Vec2(1, 1), Vec2(2, -kInf), Vec2(3, 0), Vec2(4, 4)};
  CHECK_REFUSED(InvalidArgument, StrokeElement::bezier(curve, 4), "control point 2 is not finite");
  const Vec2 fine[6] = {Vec2(0, 0), Vec2(1, 1), Vec2(2, 0), Vec2(3, 0), Vec2(4, 4), Vec2(5, 5)};
  for (const int count : {0, 1, 2, 6, -1})
    CHECK_REFUSED(InvalidArgument, StrokeElement::bezier(fine, count), "");
  CHECK_REFUSED(InvalidArgument, StrokeElement::bezier(nullptr, 0), "");
  // -0 and denormals are finite: accepted, and the element evaluates to finite points.
  const StrokeElement line = StrokeElement::line(Vec2(-0.0, -0.0), Vec2(kDenormal, -kDenormal));
  CHECK(line.degree == 1);
  CHECK(line.point(0.5).allFinite());
  CHECK(std::isfinite(line.arc_length()));
  const StrokeElement cubic = StrokeElement::bezier(fine, 4);
  CHECK(cubic.degree == 3);
  CHECK(cubic.kind == ElementKind::bezier);
  CHECK(cubic.end() == fine[3]);
  // A zero-length element's tangent falls back and stays a unit vector.
  const StrokeElement dot = StrokeElement::line(Vec2(1, 1), Vec2(1, 1));
  CHECK(dot.unit_tangent(0.5).norm() == Approx(1.0));
}

TEST_CASE(
    "unseen12j: nearest_point refuses NaN, infinite and beyond-1e150 input, a degree outside 1..4 and bad "
    "options, naming each",
    "[unseen12j]") {
  const StrokeElement quadratic = element_of({Vec2(0, 0), Vec2(0.01, 0.02), Vec2(0.02, 0)});
  CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(kNaN, 0)), "nan");
  CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(0, kInf)), "inf");
  CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(2e150, 0)), "");
  StrokeElement bad_control = quadratic;
  bad_control.control[1] = Vec2(kNaN, 0);
  CHECK_REFUSED(InvalidArgument, nearest_point(bad_control, Vec2(0, 0)), "");
  for (const int degree : {0, 5, -1, 1000}) {
    StrokeElement odd = quadratic;
    odd.degree = degree;
    CHECK_REFUSED(InvalidArgument, nearest_point(odd, Vec2(0, 0)), "degree");
  }
  for (const double tolerance : {0.0, -1e-12, kNaN, kInf, -0.0}) {
    NearestPointOptions options;
    options.tolerance = tolerance;
    CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(0, 0), options), "tolerance");
  }
  NearestPointOptions starts;
  starts.method = NearestPointMethod::newton;
  starts.newton_starts = 0;
  CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(0, 0), starts), "newton_starts");
  NearestPointOptions iterations;
  iterations.method = NearestPointMethod::newton;
  iterations.newton_iterations = 0;
  CHECK_REFUSED(InvalidArgument, nearest_point(quadratic, Vec2(0, 0), iterations), "newton_iterations");
  // At the documented bound of 1e150 the answer is finite, for every method and degree.
  for (const NearestPointMethod method :
       {NearestPointMethod::exact, NearestPointMethod::newton, NearestPointMethod::subdivision}) {
    NearestPointOptions options;
    options.method = method;
    for (const auto& points : {std::vector<Vec2>{Vec2(-1e150, 0), Vec2(1e150, 1e150)},
                               std::vector<Vec2>{Vec2(-1e150, 0), Vec2(0, 1e150), Vec2(1e150, 0)},
                               std::vector<Vec2>{Vec2(-1e150, 0), Vec2(0, 1e150), Vec2(1e150, -1e150),
                                                 Vec2(1e150, 1e150), Vec2(0, 0)}}) {
      const NearestPoint np = nearest_point(element_of(points), Vec2(1e150, -1e150), options);
      CHECK(np.t >= 0.0);
      CHECK(np.t <= 1.0);
      CHECK(np.foot.allFinite());
      CHECK(std::isfinite(np.distance));
    }
  }
}

TEST_CASE(
    "unseen12j: the exact nearest point is never farther than any sampled point of the element, for every "
    "degree",
    "[unseen12j]") {
  std::mt19937_64 random(1212);
  std::uniform_real_distribution<double> coordinate(-0.03, 0.03);
  std::uniform_int_distribution<int> degree_of(1, 4);
  NearestPointOptions newton;
  newton.method = NearestPointMethod::newton;
  NearestPointOptions subdivision;
  subdivision.method = NearestPointMethod::subdivision;
  subdivision.tolerance = 1e-5;
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int degree = degree_of(random);
    std::vector<Vec2> points;
    for (int i = 0; i <= degree; ++i) points.emplace_back(coordinate(random), coordinate(random));
    if (trial % 10 == 0) points[1] = points[0];  // coincident control points (B' vanishes at an end)
    const StrokeElement element = element_of(points);
    const Vec2 p(coordinate(random) * 1.5, coordinate(random) * 1.5);
    const NearestPoint exact = nearest_point(element, p);
    REQUIRE(exact.t >= 0.0);
    REQUIRE(exact.t <= 1.0);
    CHECK((element.point(exact.t) - exact.foot).norm() <= 1e-15);
    CHECK(std::abs((p - exact.foot).norm() - exact.distance) <= 1e-15);
    double sampled = kInf;
    for (int k = 0; k <= 2000; ++k) sampled = std::min(sampled, (element.point(k / 2000.0) - p).norm());
    CHECK(exact.distance <= sampled + 1e-15);
    // newton is local: never nearer than the global minimum; subdivision promises only a finite answer.
    const NearestPoint local = nearest_point(element, p, newton);
    CHECK(local.distance >= exact.distance - 1e-15);
    const NearestPoint greedy = nearest_point(element, p, subdivision);
    CHECK(std::isfinite(greedy.distance));
    CHECK(greedy.t >= 0.0);
    CHECK(greedy.t <= 1.0);
    ++checked;
  }
  CHECK(checked == 300);
}

TEST_CASE(
    "unseen12j: among equally near points nearest_point returns the smallest t, also on zero-length elements "
    "of every degree",
    "[unseen12j]") {
  // P on the symmetry axis of an arc, far below it: both ends are equally near, nearer than the apex.
  const StrokeElement arc = element_of({Vec2(-1, 0), Vec2(0, 2), Vec2(1, 0)});
  for (const NearestPointMethod method : {NearestPointMethod::exact, NearestPointMethod::newton}) {
    NearestPointOptions options;
    options.method = method;
    const NearestPoint np = nearest_point(arc, Vec2(0, -10), options);
    CHECK(np.t == 0.0);
    CHECK(np.distance == Approx(std::sqrt(101.0)));
  }
  // A zero-length element of any degree: every t is equally near, so t = 0.
  for (int degree = 1; degree <= 4; ++degree) {
    const std::vector<Vec2> points(static_cast<std::size_t>(degree) + 1, Vec2(0.01, -0.02));
    const StrokeElement dot = element_of(points);
    const NearestPoint np = nearest_point(dot, Vec2(0.04, 0.02));
    INFO("degree " << degree);
    CHECK(np.t == 0.0);
    CHECK(np.foot == Vec2(0.01, -0.02));
    CHECK(np.distance == Approx(0.05));
  }
}

TEST_CASE("unseen12j: distance_to_elements of no element is infinity, of several the least, and refuses NaN",
          "[unseen12j]") {
  CHECK(distance_to_elements({}, Vec2(0, 0)) == kInf);
  const std::vector<StrokeElement> elements{element_of({Vec2(0, 0), Vec2(0.01, 0)}),
                                            element_of({Vec2(0.01, 0), Vec2(0.02, 0.01), Vec2(0.03, 0)}),
                                            element_of({Vec2(0.03, 0), Vec2(0.03, 0)})};
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> coordinate(-0.02, 0.05);
  for (int i = 0; i < 200; ++i) {
    const Vec2 p(coordinate(random), coordinate(random));
    double least = kInf;
    for (const StrokeElement& element : elements) least = std::min(least, nearest_point(element, p).distance);
    CHECK(distance_to_elements(elements, p) == least);
  }
  CHECK_REFUSED(InvalidArgument, distance_to_elements(elements, Vec2(kNaN, kNaN)), "");
  // With an empty span a NaN point has nothing to be refused by, but must not give NaN.
  const double none = [&] {
    try {
      return distance_to_elements({}, Vec2(kNaN, 0));
    } catch (const InvalidArgument&) {
      return kInf;
    }
  }();
  CHECK(none == kInf);
}

TEST_CASE(
    "unseen12j: the nearest-point tracker refuses bad options, ignores hostile updates and copies as a value",
    "[unseen12j]") {
  {
    NearestPointTrackerOptions o;
    o.global_check_period = 0;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "global_check_period");
  }
  {
    NearestPointTrackerOptions o;
    o.switch_hysteresis_m = -1e-9;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "switch_hysteresis_m");
    o.switch_hysteresis_m = kNaN;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "switch_hysteresis_m");
  }
  {
    NearestPointTrackerOptions o;
    o.newton_iterations = 0;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "newton_iterations");
  }
  {
    NearestPointTrackerOptions o;
    o.tolerance = 0.0;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "tolerance");
    o.tolerance = kInf;
    CHECK_REFUSED(InvalidArgument, NearestPointTracker(o), "tolerance");
  }
  NearestPointTrackerOptions zero_hysteresis;
  zero_hysteresis.switch_hysteresis_m = 0.0;  // >= 0: allowed
  CHECK_NOTHROW(NearestPointTracker(zero_hysteresis));

  const StrokeElement cubic = element_of({Vec2(0, 0), Vec2(0.01, 0.02), Vec2(0.02, -0.02), Vec2(0.03, 0)});
  NearestPointTracker tracker;
  // Nothing tracked yet: a hostile update returns t = 0, foot (0, 0), distance 0 and tracks nothing.
  const NearestPoint first = tracker.update(cubic, Vec2(kNaN, 0));
  CHECK(first.t == 0.0);
  CHECK(first.foot == Vec2::Zero());
  CHECK(first.distance == 0.0);
  CHECK_FALSE(tracker.tracking());
  const NearestPoint good = tracker.update(cubic, Vec2(0.015, 0.004));
  CHECK(tracker.tracking());
  CHECK(good.distance == Approx(nearest_point(cubic, Vec2(0.015, 0.004)).distance).margin(1e-12));
  StrokeElement wrong_degree = cubic;
  wrong_degree.degree = 9;
  for (const NearestPoint& after :
       {tracker.update(cubic, Vec2(kInf, 0)), tracker.update(cubic, Vec2(1e151, 0)),
        tracker.update(wrong_degree, Vec2(0, 0))}) {
    CHECK(after.t == good.t);
    CHECK(after.foot == good.foot);
    CHECK(after.distance == good.distance);
  }
  CHECK(tracker.tracking());
  // A copy is an independent value that continues exactly as the original.
  NearestPointTracker copy = tracker;
  for (int tick = 0; tick < 100; ++tick) {
    const Vec2 p(0.0003 * tick, 0.003 * std::sin(tick * 0.1));
    const NearestPoint a = tracker.update(cubic, p);
    const NearestPoint b = copy.update(cubic, p);
    CHECK(a.t == b.t);
    CHECK(a.distance == b.distance);
  }
  tracker.reset();
  CHECK_FALSE(tracker.tracking());
  CHECK(copy.tracking());
}

TEST_CASE("unseen12j: Scene::lay_out refuses every layout field at and past its range, naming it",
          "[unseen12j]") {
  const std::vector<Character> one{embedded_character(U'十')};
  const auto refused_with = [&](auto set, double value, const char* field) {
    SceneLayout layout;
    set(layout, value);
    INFO(field << " = " << value);
    CHECK_REFUSED(InvalidArgument, Scene::lay_out(one, layout), field);
  };
  const auto accepted_with = [&](auto set, double value) {
    SceneLayout layout;
    set(layout, value);
    INFO("value " << value);
    CHECK_NOTHROW(Scene::lay_out(one, layout));
  };
  const auto size = [](SceneLayout& l, double v) { l.character_size_m = v; };
  const auto spacing = [](SceneLayout& l, double v) { l.spacing_m = v; };
  const auto margin = [](SceneLayout& l, double v) { l.box_margin_m = v; };
  const auto radius = [](SceneLayout& l, double v) { l.start_radius_m = v; };
  const auto centre_x = [](SceneLayout& l, double v) { l.centre_m.x() = v; };
  const auto paper_z = [](SceneLayout& l, double v) { l.paper_z_m = v; };
  for (const double v : {0.0, -0.0, -0.06, kNaN, kInf, 1.0000001, 1e308, kDenormal * 0})
    refused_with(size, v, "character_size_m");
  for (const double v : {0.0, -1.0, kNaN, kInf, 1.5}) refused_with(spacing, v, "spacing_m");
  for (const double v : {-1e-9, kNaN, 0.1000001, 1e308}) refused_with(margin, v, "box_margin_m");
  for (const double v : {0.0, -0.0, kNaN, 0.1000001}) refused_with(radius, v, "start_radius_m");
  for (const double v : {1.0000001, -1.0000001, kNaN, kInf, -1e308}) refused_with(centre_x, v, "centre_m");
  for (const double v : {1.0000001, kNaN, -kInf}) refused_with(paper_z, v, "paper_z_m");
  accepted_with(size, 1.0);
  accepted_with(size, kDenormal);  // (0, 1] m: a denormal side is positive
  accepted_with(margin, 0.0);
  accepted_with(margin, 0.1);
  accepted_with(radius, 0.1);
  accepted_with(centre_x, -1.0);
  accepted_with(centre_x, -0.0);
  accepted_with(paper_z, 1.0);
  // The count: kMaxSceneCharacters is allowed, one more is refused naming the limit.
  CHECK_NOTHROW(check_scene_size(kMaxSceneCharacters, "text"));
  CHECK_REFUSED(InvalidArgument, check_scene_size(kMaxSceneCharacters + 1, "my text"),
                "my text: 1001 characters");
  const std::vector<Character> too_many(kMaxSceneCharacters + 1, embedded_character(U'十'));
  CHECK_REFUSED(InvalidArgument, Scene::lay_out(too_many), "1000");
}

TEST_CASE(
    "unseen12j: an empty scene and a character of no strokes: the renderer writes nothing and the scorers "
    "say why",
    "[unseen12j]") {
  static const Scene empty = Scene::lay_out({});
  CHECK(empty.characters.empty());
  CHECK(empty.stroke_count() == 0);
  Renderer renderer(empty, ForceLawParameters{}, desktop_device());
  DeviceState state;
  for (int tick = 0; tick < 50; ++tick) {
    state.time_s = tick * 1e-3;
    state.position_m = Vec3(0.0, 0.0, 0.001 - tick * 1e-4);  // down through the paper
    const RenderOutput out = renderer.tick(state);
    CHECK(out.force_n.allFinite());
    CHECK(out.finished);
  }
  CHECK_REFUSED(InvalidArgument, writing_metrics(empty, std::vector<PenSample>{}), "");
  ActiveStroke active(empty);
  CHECK(active.finished());
  active.begin(Vec2(0, 0));
  CHECK(active.advance(Vec2(0.01, 0)).stroke_completed == false);
  CHECK(active.lift().stroke_completed == false);
  CHECK(active.stroke() == nullptr);
  CHECK(active.element() == nullptr);

  Character nothing;
  nothing.code_point = U'十';
  nothing.source = "test";
  const Scene hollow = Scene::lay_out({nothing});
  REQUIRE(hollow.characters.size() == 1);
  CHECK(hollow.stroke_count() == 0);
  CHECK_REFUSED(InvalidArgument, score_trace(hollow.characters[0], std::vector<PenSample>{}), "");
  CHECK_REFUSED(InvalidArgument, QuizSession(hollow.characters[0]), "");
  // A stroke past the end of the character.
  const PlacedCharacter& cross = scene_of(U'十').characters[0];
  const std::vector<Vec2> path = cross.strokes[0].median_m;
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, 2, path, 0.005), "2");
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, std::size_t(-1), path, 0.005), "");
}

TEST_CASE(
    "unseen12j: hanzi-writer JSON at its bounds: no medians, 129 medians, a one-point median, 1e400, depth "
    "17",
    "[unseen12j]") {
  const auto medians_json = [](std::size_t count, const std::string& median) {
    std::string text = R"({"medians": [)";
    for (std::size_t i = 0; i < count; ++i) text += (i ? "," : "") + median;
    return text + "]}";
  };
  const std::string two_points = "[[100,100],[900,100]]";
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(medians_json(0, two_points), U'十', "t.json"), "t.json");
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(medians_json(129, two_points), U'十', "t.json"),
                "/medians");
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(medians_json(1, "[[100,100]]"), U'十', "t.json"),
                "/medians/0");
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(medians_json(1, "[[100,100],[100,100]]"), U'十', "t.json"),
                "/medians/0");
  CHECK_REFUSED(DataError,
                parse_hanzi_writer_json(medians_json(1, "[[100,1e400],[900,100]]"), U'十', "t.json"),
                "/medians/0/0/1");
  CHECK_REFUSED(DataError,
                parse_hanzi_writer_json(medians_json(1, "[[100,100],[100001,100]]"), U'十', "t.json"),
                "/medians/0/1/0");
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(medians_json(1, "[[100,100],[NaN,100]]"), U'十', "t.json"),
                "t.json");
  std::string deep = R"({"medians": )";
  for (int i = 0; i < 17; ++i) deep += "[";
  for (int i = 0; i < 17; ++i) deep += "]";
  CHECK_REFUSED(DataError, parse_hanzi_writer_json(deep + "}", U'十', "deep.json"), "deep.json");
  CHECK_REFUSED(DataError, parse_hanzi_writer_json("", U'十', "empty.json"), "empty.json");

  // 128 medians are allowed; a character of 64 distinct strokes is fitted, placed and scored.
  CHECK(parse_hanzi_writer_json(medians_json(128, two_points), U'十', "t.json").medians.size() == 128);
  std::string many = R"({"medians": [)";
  for (int i = 0; i < 64; ++i) {
    const int y = 850 - i * 14;
    const std::string row = std::to_string(y);
    many.append(i ? "," : "").append("[[100,").append(row).append("],[900,").append(row).append("]]");
  }
  const CharacterData data = parse_hanzi_writer_json(many + "]}", U'鼎', "many.json");
  const Character fitted = fit_character(data.code_point, data.medians, data.source);
  REQUIRE(fitted.strokes.size() == 64);
  const Scene scene = Scene::lay_out({fitted});
  CHECK(scene.stroke_count() == 64);
  const CharacterScore score = score_trace(scene.characters[0], std::vector<PenSample>{});
  CHECK(score.strokes.size() == 64);
  CHECK(score.strokes_written == 0);
  CHECK(score.missing_strokes.size() == 64);
  CHECK_FALSE(score.completed_in_order);
  CHECK_FALSE(score.totals.deviation.has_value());
}

TEST_CASE("unseen12j: fit_stroke on one point, duplicate points, no point, NaN, 1e150 and 20000 points",
          "[unseen12j]") {
  const std::vector<Vec2> one{Vec2(500, 400)};
  const FittedStroke single = fit_stroke(one);
  REQUIRE(single.stroke.elements.size() == 1);
  CHECK(single.stroke.elements[0].kind == ElementKind::line);
  CHECK(single.stroke.elements[0].start() == single.stroke.elements[0].end());
  const std::vector<Vec2> repeated(7, Vec2(500, 400));
  const FittedStroke dot = fit_stroke(repeated);
  REQUIRE(!dot.stroke.elements.empty());
  for (const StrokeElement& e : dot.stroke.elements) CHECK(e.polygon_length() == 0.0);
  CHECK(dot.stroke.attraction_factors.size() == dot.stroke.elements.size() + 1);
  CHECK_REFUSED(InvalidArgument, fit_stroke(std::vector<Vec2>{}), "");
  CHECK_REFUSED(InvalidArgument, fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(kNaN, 1)}), "");
  CHECK_REFUSED(InvalidArgument, fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(1.0000001e150, 1)}), "");
  CHECK_NOTHROW(fit_stroke(std::vector<Vec2>{Vec2(-1e150, 0), Vec2(1e150, 1e150)}));
  FitOptions bad;
  bad.max_degree = 5;
  CHECK_REFUSED(InvalidArgument, fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(100, 0)}, bad),
                "FitOptions.max_degree = 5");
  bad = FitOptions{};
  bad.tolerance = kNaN;
  CHECK_REFUSED(InvalidArgument, fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(100, 0)}, bad), "tolerance");
  // 2 x 10^4 points on a line, -0 among them: bounded work, straight elements within the tolerance.
  std::vector<Vec2> line;
  for (int i = 0; i < 20000; ++i) line.emplace_back(i * 0.008, i % 2 ? -0.0 : 0.0);
  const FittedStroke straight = fit_stroke(line);
  REQUIRE(!straight.stroke.elements.empty());
  CHECK(straight.max_deviation <= FitOptions{}.tolerance);
  CHECK(straight.stroke.typical_id >= 1);
  CHECK(straight.stroke.typical_id <= 39);
}

TEST_CASE("unseen12j: typical strokes, the Table-3 view and classification at their edges", "[unseen12j]") {
  for (const int id : {0, 40, -1, 1000})
    CHECK_REFUSED(InvalidArgument, typical_stroke(id), std::to_string(id));
  REQUIRE(typical_strokes().size() == 39);
  for (int id = 1; id <= 39; ++id) {
    CHECK(typical_stroke(id).id == id);
    CHECK(typical_stroke_id(typical_stroke(id).acronym) == id);
  }
  CHECK_FALSE(typical_stroke_id("").has_value());
  CHECK_FALSE(typical_stroke_id("hzg").has_value());  // acronyms are upper case
  CHECK_REFUSED(InvalidArgument, classify_pieces(std::span<const StrokePiece>{}), "");
  Character odd = embedded_character(U'十');
  REQUIRE(odd.strokes.size() == 2);
  odd.strokes[1].elements[0].degree = 5;
  CHECK_REFUSED(InvalidArgument, character_table(odd), "2");
  const CharacterTable table = character_table(embedded_character(U'口'));
  CHECK(table.typical_stroke_ids.size() == 3);
  CHECK(table.feature_point_indices.size() == 3);
}

// The range of angles is (-180, 180]; a test name with an unmatched bracket would break CTest's list of
// names.
TEST_CASE(
    "unseen12j: polyline helpers keep their documented ranges: angles above -180 up to 180, no points for a "
    "bad step",
    "[unseen12j]") {
  for (const double step : {0.0, -0.0, -1.0, kNaN})
    CHECK(resample(std::vector<Vec2>{Vec2(0, 0), Vec2(1, 0)}, step).empty());
  CHECK(polyline_length(std::vector<Vec2>{}) == 0.0);
  CHECK(polyline_length(std::vector<Vec2>{Vec2(1, 1)}) == 0.0);
  CHECK(max_distance_to_polyline(std::vector<Vec2>{}, std::vector<Vec2>{Vec2(0, 0), Vec2(1, 0)}) == 0.0);
  CHECK(without_repeats(std::vector<Vec2>{Vec2(1, 1), Vec2(1, 1), Vec2(2, 2), Vec2(2, 2)}).size() == 2);
  const auto in_range = [](double deg) { return deg > -180.0 && deg <= 180.0; };
  for (const double a : {-180.0, 180.0, 540.0, -540.0, 1e308, -1e308, -0.0, 359.99999999999994, -kDenormal}) {
    INFO("wrap_deg(" << a << ") = " << wrap_deg(a));
    CHECK(in_range(wrap_deg(a)));
  }
  CHECK(wrap_deg(-180.0) == 180.0);
  for (const Vec2& v : {Vec2(-1, -0.0), Vec2(-1, 0.0), Vec2(-1, -kDenormal), Vec2(0, 0), Vec2(-0.0, -0.0)}) {
    INFO("direction_deg(" << v.transpose() << ") = " << direction_deg(v));
    CHECK(in_range(direction_deg(v)));
  }
  CHECK(direction_deg(Vec2(-1, -0.0)) == 180.0);
  CHECK(in_range(turn_deg(Vec2(1, 0), Vec2(-1, -0.0))));
}

// ---- stroke acceptance
// -----------------------------------------------------------------------------------------

TEST_CASE(
    "unseen12j: StrokeAcceptance refuses each field at and past its range by name, and compares as a value",
    "[unseen12j]") {
  const auto refused = [](double StrokeAcceptance::*field, double value, const char* name) {
    StrokeAcceptance a;
    a.*field = value;
    INFO(name << " = " << value);
    CHECK_REFUSED(InvalidArgument, a.validate(), std::string("StrokeAcceptance.") + name);
  };
  const auto accepted = [](double StrokeAcceptance::*field, double value) {
    StrokeAcceptance a;
    a.*field = value;
    INFO("value " << value);
    CHECK_NOTHROW(a.validate());
  };
  // Lengths in (0, 0.1] m.
  for (const auto& [field, name] : std::vector<std::pair<double StrokeAcceptance::*, const char*>>{
           {&StrokeAcceptance::corridor_m, "corridor_m"},
           {&StrokeAcceptance::mean_deviation_m, "mean_deviation_m"},
           {&StrokeAcceptance::shortfall_m, "shortfall_m"},
           {&StrokeAcceptance::displacement_m, "displacement_m"},
           {&StrokeAcceptance::lookahead_m, "lookahead_m"},
           {&StrokeAcceptance::follow_through_m, "follow_through_m"},
           {&StrokeAcceptance::shortfall_cap_m, "shortfall_cap_m"},
           {&StrokeAcceptance::mean_deviation_cap_m, "mean_deviation_cap_m"}}) {
    for (const double v : {0.0, -0.0, -1e-9, 0.1000001, kNaN, kInf, 1e308}) refused(field, v, name);
    accepted(field, 0.1);
    accepted(field, kDenormal);
  }
  // end_gap_m in [0, 0.1].
  accepted(&StrokeAcceptance::end_gap_m, 0.0);
  for (const double v : {-1e-12, 0.11, kNaN}) refused(&StrokeAcceptance::end_gap_m, v, "end_gap_m");
  // Fractions.
  for (const double v : {0.0, 1.0, -0.1, kNaN})
    refused(&StrokeAcceptance::shortfall_fraction, v, "shortfall_fraction");
  accepted(&StrokeAcceptance::centred_coverage_fraction, 0.0);
  for (const double v : {1.0, kNaN})
    refused(&StrokeAcceptance::centred_coverage_fraction, v, "centred_coverage_fraction");
  // The gain ratio in [1, 100].
  accepted(&StrokeAcceptance::max_gain_ratio, 1.0);
  accepted(&StrokeAcceptance::max_gain_ratio, 100.0);
  for (const double v : {0.999999, 100.000001, kNaN, kInf})
    refused(&StrokeAcceptance::max_gain_ratio, v, "max_gain_ratio");
  // Miss counts: whole numbers in [0, 1000].
  for (double StrokeAcceptance::*field :
       {&StrokeAcceptance::hint_after_misses, &StrokeAcceptance::assist_after_misses}) {
    const char* name =
        field == &StrokeAcceptance::hint_after_misses ? "hint_after_misses" : "assist_after_misses";
    accepted(field, 0.0);
    accepted(field, 1000.0);
    for (const double v : {2.5, -1.0, 1001.0, kNaN, kDenormal, 1e308}) refused(field, v, name);
  }
  const StrokeAcceptance a;
  StrokeAcceptance b = a;
  CHECK(a == b);
  b.corridor_m = std::nextafter(b.corridor_m, 1.0);
  CHECK_FALSE(a == b);
  StrokeAcceptance moved = std::move(b);
  b = a;  // a moved-from value takes a new one
  CHECK(b == a);
  CHECK_FALSE(moved == a);
}

TEST_CASE(
    "unseen12j: the tolerances that grow with the stroke stay under their caps and fractions for every "
    "length",
    "[unseen12j]") {
  const StrokeAcceptance a;
  double previous_shortfall = 0.0;
  for (const double length :
       {0.0, kDenormal, 1e-6, 0.001, 0.008, 0.011, 0.02, 0.048, 0.06, 0.1, 1.0, 1e308}) {
    INFO("L = " << length);
    const double s = a.allowed_shortfall_m(length);
    const double e = a.allowed_end_gap_m(length);
    const double d = a.allowed_mean_deviation_m(length);
    REQUIRE(std::isfinite(s));
    REQUIRE(std::isfinite(e));
    REQUIRE(std::isfinite(d));
    CHECK(s <= a.shortfall_fraction * length);
    CHECK(s <= a.shortfall_cap_m);
    CHECK(s <= a.shortfall_m + a.shortfall_per_length * length);
    CHECK(s >= previous_shortfall);
    previous_shortfall = s;
    CHECK(e >= s);
    CHECK(e >= a.displacement_m);
    CHECK(d <= a.mean_deviation_cap_m);
    CHECK(d >= std::min(a.mean_deviation_m, a.mean_deviation_cap_m));
  }
  const StrokeAcceptance doubled = a.for_character_size(0.12);
  CHECK(doubled.corridor_m == Approx(2 * a.corridor_m));
  CHECK(doubled.shortfall_cap_m == Approx(2 * a.shortfall_cap_m));
  CHECK(doubled.shortfall_fraction == a.shortfall_fraction);
  CHECK(doubled.hint_after_misses == a.hint_after_misses);
  CHECK_NOTHROW(doubled.validate());
  StrokeAcceptance absolute;
  absolute.reference_character_size_m = 0.0;
  CHECK(absolute.for_character_size(0.12) == absolute);
}

// ---- collision
// ------------------------------------------------------------------------------------------------

TEST_CASE("unseen12j: the LSE rules (a)-(d) on their boundaries, and contact inside only within the radius",
          "[unseen12j]") {
  const Vec2 a(0, 0), b(0.02, 0);
  CHECK(lse_rules_inside(a, b, a));                        // P1.PEdge == 0: the boundary counts as inside
  CHECK(lse_rules_inside(a, b, b));                        // |P1| == |PEdge|
  CHECK(lse_rules_inside(a, b, Vec2(0.01, 0.003)));        // (c)
  CHECK_FALSE(lse_rules_inside(a, b, Vec2(-0.001, 0.0)));  // (a)
  CHECK_FALSE(lse_rules_inside(a, b, Vec2(0.021, 0.0)));   // (b)
  CHECK(lse_rules_inside(a, a, Vec2(5, 5)));               // (d) start == end
  CHECK(lse_rules_inside(Vec2(-0.0, 0.0), Vec2(0.0, -0.0), Vec2(1, 1)));
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> coordinate(-0.01, 0.03);
  const std::vector<StrokeElement> elements{StrokeElement::line(a, b), StrokeElement::line(a, a),
                                            element_of({Vec2(0, 0), Vec2(0.01, 0.015), Vec2(0.02, 0)})};
  for (const StrokeElement& element : elements) {
    for (int i = 0; i < 300; ++i) {
      const Vec2 tip(coordinate(random), coordinate(random));
      const ElementContact contact = element_contact(element, tip, 0.006, NearestPointOptions{});
      if (contact.inside) CHECK(contact.nearest.distance <= 0.006);
      const ElementContact at = element_contact_at(element, tip, contact.nearest, 0.006);
      CHECK(at.inside == contact.inside);
    }
  }
  // A radius of 0: only a tip on the element can be inside.
  CHECK_FALSE(element_contact(elements[0], Vec2(0.01, 1e-9), 0.0, NearestPointOptions{}).inside);
}

// ---- render
// ---------------------------------------------------------------------------------------------------

TEST_CASE(
    "unseen12j: the force law's terms, the off-stroke friction with an aliased anchor: zero where "
    "documented, bounded, continuous",
    "[unseen12j]") {
  // Paper force: zero above and at the paper, K (z0 - z) out of it below.
  CHECK(paper_force(0.001, 0.0, 800.0) == Vec3::Zero());
  CHECK(paper_force(0.0, 0.0, 800.0) == Vec3::Zero());
  CHECK(paper_force(-0.0, 0.0, 800.0) == Vec3::Zero());
  CHECK(paper_force(-0.002, 0.0, 800.0).isApprox(Vec3(0, 0, 1.6)));
  CHECK(paper_force(0.098, 0.1, 800.0).z() > 0.0);
  // Attraction: zero on the foot, towards it, linear.
  CHECK(attraction_force(Vec2(1, 1), Vec2(1, 1), 400.0, 1.5) == Vec2::Zero());
  CHECK(attraction_force(Vec2(0, 0), Vec2(0.001, 0), 400.0, 1.0).isApprox(Vec2(0.4, 0)));
  // Resistance: only against writing backwards.
  const Vec2 tangent(1, 0);
  CHECK(resistance_force(Vec2(0.05, 0.02), tangent, 15.0) == Vec2::Zero());
  CHECK(resistance_force(Vec2(0.0, 0.05), tangent, 15.0) == Vec2::Zero());
  CHECK(resistance_force(Vec2(-0.02, 0.01), tangent, 15.0).isApprox(Vec2(0.3, 0)));
  // Friction: at most mu N, opposing the motion, continuous at the stick band.
  const double mu = 0.15, normal = 2.0, band = 0.02;
  CHECK(friction_force(Vec2::Zero(), normal, mu, band) == Vec2::Zero());
  for (const double speed : {1e-9, 0.001, 0.0199999, 0.02, 0.0200001, 0.5, 1e3, 1e300}) {
    const Vec2 f = friction_force(Vec2(speed, 0), normal, mu, band);
    INFO("speed " << speed);
    REQUIRE(f.allFinite());
    CHECK(f.norm() <= mu * normal * (1 + 1e-12));
    CHECK(f.x() <= 0.0);
  }
  CHECK(friction_force(Vec2(std::nextafter(band, 0.0), 0), normal, mu, band).x() ==
        Approx(friction_force(Vec2(std::nextafter(band, 1.0), 0), normal, mu, band).x()));
  // Off-stroke damper: zero below v0, at most B |v|, continuous at v0 and 2 v0.
  const double damping = 25.0, v0 = 0.005;
  CHECK(off_stroke_resistance(Vec2(0.004, 0), damping, v0) == Vec2::Zero());
  for (const double speed : {0.0, 0.005, 0.0075, 0.01, 0.02, 1.0}) {
    const Vec2 f = off_stroke_resistance(Vec2(0, speed), damping, v0);
    CHECK(f.norm() <= damping * speed * (1 + 1e-12));
  }
  for (const double edge : {v0, 2 * v0}) {
    const double below = off_stroke_resistance(Vec2(std::nextafter(edge, 0.0), 0), damping, v0).x();
    const double above = off_stroke_resistance(Vec2(std::nextafter(edge, 1.0), 0), damping, v0).x();
    CHECK(below == Approx(above).margin(1e-9));
  }
  CHECK(off_stroke_resistance(Vec2(0.1, 0), damping, v0).isApprox(Vec2(-2.5, 0)));
  // The off-stroke friction with its anchor aliasing the tip, and an anchor far away.
  Vec2 tip(0.01, 0.02);
  // The tip passed as its own anchor: no spring, no motion, no NaN.
  const Vec2 self = off_stroke_friction(tip, tip, 0.5, 0.001);
  CHECK(self == Vec2::Zero());
  CHECK(tip == Vec2(0.01, 0.02));
  Vec2 anchor(0.5, -0.3);
  const Vec2 far = off_stroke_friction(tip, anchor, 0.5, 0.001);
  REQUIRE(far.allFinite());
  CHECK(far.norm() <= 0.5 * (1 + 1e-12));
  CHECK((anchor - tip).norm() <= 0.001 * (1 + 1e-9));
  CHECK(far.dot(anchor - tip) >= 0.0);  // towards the anchor
  Vec2 near_anchor = tip + Vec2(0.0005, 0);
  const Vec2 held = off_stroke_friction(tip, near_anchor, 0.5, 0.001);
  CHECK(near_anchor == tip + Vec2(0.0005, 0));  // within the travel: the anchor stays
  CHECK(held.isApprox(Vec2(0.25, 0)));
}

TEST_CASE(
    "unseen12j: the constraint taper is 1 inside, 0 from the radius out, monotone and continuous in between",
    "[unseen12j]") {
  for (const double band : {0.0, 1e-6, 0.002, 0.006}) {
    const double radius = 0.006;
    double previous = 1.0;
    double largest_step = 0.0;
    for (int i = 0; i <= 12000; ++i) {
      const double d = i * 1e-6;
      const double w = constraint_taper(d, radius, band);
      REQUIRE(std::isfinite(w));
      CHECK(w >= 0.0);
      CHECK(w <= 1.0);
      CHECK(w <= previous);
      largest_step = std::max(largest_step, previous - w);
      previous = w;
      if (d < radius - band - 1e-12) CHECK(w == 1.0);
      if (d > radius + 1e-12) CHECK(w == 0.0);
    }
    INFO("band " << band);
    if (band >= 0.002) CHECK(largest_step < 0.01);  // no step with a band of its own width
  }
  CHECK(constraint_taper(1e308, 0.006, 0.002) == 0.0);
  CHECK(constraint_taper(kInf, 0.006, 0.002) == 0.0);
  CHECK(constraint_taper(0.0, 0.006, 0.002) == 1.0);
}

TEST_CASE("unseen12j: the safety chain refuses bad parameters by name and keeps every limit on hostile input",
          "[unseen12j]") {
  const auto with = [](auto set) {
    SafetyChainParameters p;
    p.max_force_n = 3.0;
    set(p);
    return p;
  };
  CHECK_REFUSED(InvalidArgument, SafetyChain(SafetyChainParameters{}, 1000.0), "max_force_n");
  CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto& p) { p.max_force_n = kNaN; }), 1000.0),
                "max_force_n");
  CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto& p) { p.max_force_n = 100.0001; }), 1000.0),
                "max_force_n");
  CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto& p) { p.max_continuous_force_n = 3.5; }), 1000.0),
                "max_continuous_force_n");
  CHECK_REFUSED(InvalidArgument,
                SafetyChain(with([](auto& p) { p.continuous_time_constant_s = 0.0; }), 1000.0),
                "continuous_time_constant_s");
  CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto& p) { p.start_ramp_n_per_s = -1.0; }), 1000.0),
                "start_ramp_n_per_s");
  CHECK_REFUSED(InvalidArgument,
                SafetyChain(with([](auto& p) { p.max_force_change_n_per_tick = kInf; }), 1000.0),
                "max_force_change_n_per_tick");
  CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto& p) { p.low_pass_cutoff_hz = 500.0; }), 1000.0),
                "low_pass_cutoff_hz");  // not under the Nyquist frequency
  for (const double rate : {0.0, -1000.0, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, SafetyChain(with([](auto&) {}), rate), "");

  SafetyChainParameters p;
  p.max_force_n = 3.0;
  p.max_continuous_force_n = 1.5;
  p.low_pass_cutoff_hz = 100.0;
  SafetyChain chain(p, 1000.0);
  std::mt19937_64 random(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<double> scales{1.0, 10.0, 1e308, kDenormal, 0.0};
  Vec3 previous = Vec3::Zero();
  std::uint64_t non_finite = 0;
  SafetyChain copy = chain;  // a value: the copy continues alike
  for (int tick = 1; tick <= 5000; ++tick) {
    Vec3 input(unit(random), unit(random), unit(random));
    input *= scales[static_cast<std::size_t>(tick) % scales.size()];
    if (tick % 97 == 0) input.x() = kNaN;
    if (tick % 101 == 0) input.z() = -kInf;
    const bool bad = !input.allFinite();
    non_finite += bad ? 1 : 0;
    const SafetyResult out = chain.apply(input);
    const SafetyResult twin = copy.apply(input);
    REQUIRE(out.force_n.allFinite());
    CHECK(out.force_n == twin.force_n);
    CHECK(out.force_n.norm() <= 3.0 * (1 + 1e-12));
    CHECK(out.force_n.norm() <= 20.0 * tick * 1e-3 + 1e-12);  // start ramp
    if (bad) {
      CHECK(out.force_n == Vec3::Zero());
      CHECK((out.limits & safety_non_finite) != 0);
    } else {
      CHECK((out.force_n - previous).norm() <= 0.25 * (1 + 1e-12));
    }
    previous = out.force_n;
  }
  CHECK(chain.non_finite_count() == non_finite);
  CHECK(std::isfinite(chain.rms_force_n()));
  chain.reset();
  CHECK(chain.last_output() == Vec3::Zero());
  CHECK(chain.non_finite_count() == non_finite);  // not cleared by reset
}

TEST_CASE("unseen12j: Colgate's bound and the passivity controller at their edges", "[unseen12j]") {
  CHECK(colgate_stiffness_bound(0.5, 1000.0) == Approx(1000.0));
  CHECK(colgate_stiffness_bound(0.0, 1000.0) == 0.0);
  CHECK(colgate_stiffness_bound(0.5, 1000.0, 0.5) == 0.0);
  CHECK(colgate_stiffness_bound(0.5, 1000.0, 2.0) == 0.0);  // B >= b: 0, never negative
  CHECK_REFUSED(InvalidArgument, colgate_stiffness_bound(-0.1, 1000.0), "");
  CHECK_REFUSED(InvalidArgument, colgate_stiffness_bound(0.5, 0.0), "");
  CHECK_REFUSED(InvalidArgument, colgate_stiffness_bound(0.5, kNaN), "");
  CHECK_REFUSED(InvalidArgument, colgate_stiffness_bound(kInf, 1000.0), "");
  CHECK_REFUSED(InvalidArgument, colgate_stiffness_bound(0.5, 1000.0, -1.0), "");

  PassivityParameters bad;
  bad.max_damping_n_s_per_m = 0.0;
  CHECK_REFUSED(InvalidArgument, bad.validate(), "max_damping_n_s_per_m");
  bad = PassivityParameters{};
  bad.min_speed_m_s = kNaN;
  CHECK_REFUSED(InvalidArgument, PassivityController(bad, 1000.0), "min_speed_m_s");
  CHECK_REFUSED(InvalidArgument, PassivityController(PassivityParameters{}, 0.0), "");

  PassivityParameters on;
  on.enabled = true;
  PassivityController controller(on, 1000.0);
  const Vec3 f(0.5, 0, 0);
  controller.apply(Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), f);
  controller.apply(Vec3(0.001, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0), f);  // the environment produced energy
  const double energy = controller.observed_energy_j();
  CHECK(energy < 0.0);
  for (const Vec3& hostile : {Vec3(kNaN, 0, 0), Vec3(0, kInf, 0)}) {
    const Vec3 out = controller.apply(hostile, Vec3(1, 0, 0), Vec3(1, 0, 0), f);
    CHECK(controller.observed_energy_j() == energy);
    static_cast<void>(out);
  }
  const Vec3 damped = controller.apply(Vec3(0.002, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 0), f);
  REQUIRE(damped.allFinite());
  CHECK(controller.damping_n_s_per_m() <= on.max_damping_n_s_per_m);
  CHECK(controller.damping_n_s_per_m() >= 0.0);
}

TEST_CASE("unseen12j: the renderer refuses a rate, a device and a force law out of range, naming the field",
          "[unseen12j]") {
  const Scene& scene = scene_of(U'十');
  for (const double rate : {99.999, 100000.001, kNaN, kInf, 0.0, -1000.0}) {
    RendererOptions options;
    options.rate_hz = rate;
    CHECK_REFUSED(InvalidArgument, Renderer(scene, ForceLawParameters{}, desktop_device(), options),
                  "rate_hz");
  }
  for (const double rate : {100.0, 100000.0}) {
    RendererOptions options;
    options.rate_hz = rate;
    CHECK_NOTHROW(Renderer(scene, ForceLawParameters{}, desktop_device(), options));
  }
  for (const double max_force : {0.0, -1.0, kNaN}) {
    DeviceInfo device = desktop_device();
    device.max_force_n = max_force;
    CHECK_REFUSED(InvalidArgument, Renderer(scene, ForceLawParameters{}, device), "max_force_n");
  }
  ForceLawParameters wide_taper;
  wide_taper.constraint_taper_m = 0.0061;
  CHECK_REFUSED(InvalidArgument, Renderer(scene, wide_taper, desktop_device()), "constraint_taper_m");
  ForceLawParameters radius;
  radius.constraint_radius_m = 0.0;
  CHECK_REFUSED(InvalidArgument, radius.validate(), "ForceLawParameters.constraint_radius_m");
  radius.constraint_radius_m = 0.1000001;
  CHECK_REFUSED(InvalidArgument, radius.validate(), "ForceLawParameters.constraint_radius_m");
  ForceLawParameters nan_stiffness;
  nan_stiffness.guidance_stiffness_n_per_m = kNaN;
  CHECK_REFUSED(InvalidArgument, nan_stiffness.validate(), "guidance_stiffness_n_per_m");
  ForceLawParameters coarse;
  coarse.nearest.tolerance = 1.1e-3;  // coarser than a force law takes
  CHECK_REFUSED(InvalidArgument, coarse.validate(), "tolerance");
  ForceLawParameters fading;
  fading.guidance_law = FadingGuidance{1.5};
  CHECK_REFUSED(InvalidArgument, fading.validate(), "FadingGuidance.gain");
  ForceLawParameters lead;
  lead.guidance_law = TimingGuidance{0.04, 0.007};  // more than R_res
  CHECK_REFUSED(InvalidArgument, lead.validate(), "max_lead_m");
}

namespace {
// A device state at `position` with the velocity of the last step.
DeviceState state_at(double time_s, const Vec3& position, const Vec3& velocity) {
  DeviceState state;
  state.time_s = time_s;
  state.position_m = position;
  state.velocity_m_s = velocity;
  return state;
}
}  // namespace

TEST_CASE(
    "unseen12j: hostile device states never give the renderer a force above its cap or a non-finite one",
    "[unseen12j]") {
  const Scene& scene = scene_of(U'十');
  RendererOptions options;
  options.safety.max_force_n = 2.0;
  Renderer renderer(scene, ForceLawParameters{}, desktop_device(), options);
  const Vec2 start = scene.characters[0].strokes[0].start();
  std::mt19937_64 random(99);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<double> hostile{kNaN, kInf, -kInf, 1e308, -1e308, 10.0000001, -11.0};
  int rejected = 0;
  for (int tick = 0; tick < 6000; ++tick) {
    const double t = tick * 1e-3;
    Vec3 position(start.x() + 0.01 * unit(random), start.y() + 0.01 * unit(random),
                  -0.01 * std::abs(unit(random)));
    Vec3 velocity(unit(random), unit(random), unit(random));
    double time = t;
    bool bad = false;
    if (tick % 13 == 0) {
      const double value = hostile[static_cast<std::size_t>(tick / 13) % hostile.size()];
      switch ((tick / 13) % 3) {
        case 0:
          position.x() = value;
          break;
        case 1:
          velocity.z() = value;
          break;
        default:
          time = std::isfinite(value) ? t : value;
          break;
      }
      bad = !(std::isfinite(position.x()) && std::abs(position.x()) <= kMaxDeviceReadingM) ||
            !std::isfinite(velocity.z()) || !std::isfinite(time);
    }
    if (tick % 17 == 0) position.y() = -0.0, velocity.x() = kDenormal;  // finite: accepted
    const RenderOutput out = renderer.tick(state_at(time, position, velocity));
    REQUIRE(out.force_n.allFinite());
    CHECK(out.force_n.norm() <= 2.0 * (1 + 1e-12));
    if (bad) {
      CHECK(out.input_rejected);
      CHECK(out.force_n == Vec3::Zero());
      ++rejected;
    }
  }
  CHECK(rejected > 100);
  // A rejected reading never counts as finishing anything.
  CHECK(renderer.active().strokes_written() <= 2);
}

TEST_CASE(
    "unseen12j: a pen pressed 0.1 m into the paper meets at most the peak force, and a pen at rest off the "
    "stroke none",
    "[unseen12j]") {
  const Scene& scene = scene_of(U'十');
  for (const double cap : {0.0, 1.0}) {
    RendererOptions options;
    options.safety.max_force_n = cap;             // 0: the device's 7.9 N
    options.safety.max_continuous_force_n = cap;  // 0: the device's 1.75 N; not above a peak that is set
    options.safety.max_force_change_n_per_tick = 0.0;
    options.safety.start_ramp_n_per_s = 0.0;
    Renderer renderer(scene, ForceLawParameters{}, desktop_device(), options);
    const double limit = cap > 0 ? cap : desktop_device().max_force_n;
    double largest = 0.0;
    for (int tick = 0; tick < 2000; ++tick) {
      const RenderOutput out = renderer.tick(
          state_at(tick * 1e-3, Vec3(0.0, 0.0, -0.1 * std::min(1.0, tick / 500.0)), Vec3::Zero()));
      largest = std::max(largest, out.force_n.norm());
      CHECK(out.force_n.norm() <= limit * (1 + 1e-12));
    }
    INFO("cap " << cap);
    CHECK(largest >= limit * 0.999);  // the cap is reached, so the check can fail
  }
  // Hovering 5 cm above the paper, or resting on it 4 cm from every stroke, the pen feels nothing.
  Renderer renderer(scene, ForceLawParameters{}, desktop_device());
  for (const Vec3& where : {Vec3(0.0, 0.0, 0.05), Vec3(0.2, 0.2, 0.0), Vec3(0.04, 0.04, 0.001)}) {
    renderer.reset();
    RenderOutput out;
    for (int tick = 0; tick < 600; ++tick) out = renderer.tick(state_at(tick * 1e-3, where, Vec3::Zero()));
    INFO("pen at " << where.transpose());
    CHECK(out.force_n.norm() == 0.0);
    CHECK_FALSE(out.in_constraint_space);
  }
}

TEST_CASE("unseen12j: the rendered force stays continuous across an element boundary without the rate limit",
          "[unseen12j]") {
  const Scene& scene = scene_of(U'乙');
  const PlacedStroke& stroke = scene.characters[0].strokes[0];
  REQUIRE(stroke.elements.size() >= 2);
  RendererOptions options;
  options.safety.max_force_change_n_per_tick = 0.0;  // only the smoothing keeps the force continuous
  Renderer renderer(scene, ForceLawParameters{}, desktop_device(), options);
  const std::vector<Vec2> path = densely(stroke.centre_line.points_m, 0.04 * 1e-3);  // 40 mm/s at 1 kHz
  REQUIRE(path.size() > 100);
  double t = 0.0;
  Vec3 previous_force = Vec3::Zero();
  Vec3 previous_position(path[0].x(), path[0].y(), 0.002);
  double largest_step = 0.0, step_at_switch = 0.0;
  std::size_t element_changes = 0, last_element = 0;
  const auto tick = [&](const Vec3& position) {
    const Vec3 velocity = (position - previous_position) / 1e-3;
    const RenderOutput out = renderer.tick(state_at(t, position, velocity));
    t += 1e-3;
    previous_position = position;
    const double step = (out.force_n - previous_force).norm();
    largest_step = std::max(largest_step, step);
    if (out.element != last_element) {
      ++element_changes;
      step_at_switch = std::max(step_at_switch, step);
      last_element = out.element;
    }
    previous_force = out.force_n;
    return out;
  };
  for (int i = 0; i <= 250; ++i) tick(Vec3(path[0].x(), path[0].y(), 0.002 - i * 1e-5));  // down at 10 mm/s
  for (const Vec2& p : path) tick(Vec3(p.x(), p.y(), -0.0005));
  for (int i = 0; i <= 250; ++i) tick(Vec3(path.back().x(), path.back().y(), -0.0005 + i * 1e-5));
  INFO("largest step " << largest_step << " N, at an element switch " << step_at_switch << " N");
  CHECK(element_changes >= 1);
  CHECK(largest_step < 0.25);
  CHECK(step_at_switch < 0.25);
  CHECK(renderer.active().strokes_written() == 1);
}

TEST_CASE(
    "unseen12j: the per-repetition rules at and past their ranges: gains in [0, 1], bands within their "
    "bounds",
    "[unseen12j]") {
  CHECK(next_guidance_gain(1.0, 0.0) == Approx(0.8));
  CHECK(next_guidance_gain(0.0, 1e308) == 1.0);  // clamped, never inf
  CHECK(next_guidance_gain(-0.0, 0.0) == 0.0);
  for (const double gain : {1.0000001, -1e-12, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, next_guidance_gain(gain, 0.001), "");
  for (const double error : {-1e-12, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, next_guidance_gain(0.5, error), "");
  FadingRule bad_rule;
  bad_rule.forgetting_factor = 1.5;
  CHECK_REFUSED(InvalidArgument, next_guidance_gain(0.5, 0.001, bad_rule), "forgetting_factor");
  const AssistBandRule band_rule;
  CHECK(next_assist_band(0.001, 1e308) == band_rule.min_band_m);
  CHECK(next_assist_band(0.001, 0.0) ==
        Approx(std::min(0.001 + band_rule.target_error_m, band_rule.max_band_m)));
  CHECK(next_assist_band(1e308, 0.0) == band_rule.max_band_m);
  for (const double band : {-1e-12, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, next_assist_band(band, 0.001), "");
  AssistBandRule inverted;
  inverted.min_band_m = 0.003;
  inverted.max_band_m = 0.002;
  CHECK_REFUSED(InvalidArgument, inverted.validate(), "max_band_m");
  CHECK(skill_adaptive_mode(kNaN) == GuidanceMode::fixed);
  CHECK(skill_adaptive_mode(0.002) == GuidanceMode::fixed);
  CHECK(skill_adaptive_mode(-0.0) == GuidanceMode::error_amplification);
  CHECK_REFUSED(InvalidArgument, skill_adaptive_mode(kInf), "inf");
  CHECK_REFUSED(InvalidArgument, skill_adaptive_mode(-1e-300), "");
  SkillAdaptiveRule zero_threshold;
  zero_threshold.threshold_m = 0.0;
  CHECK_REFUSED(InvalidArgument, skill_adaptive_mode(0.001, zero_threshold), "threshold_m");

  for (const AdaptiveGuidance adapts :
       {AdaptiveGuidance::fading, AdaptiveGuidance::assist_as_needed, AdaptiveGuidance::skill_adaptive}) {
    GuidanceSchedule schedule;
    schedule.adapts = adapts;
    schedule.start_gain = 0.3;
    const RepetitionGuidance first = schedule.start();
    const RepetitionGuidance none = schedule.next(first, std::nullopt);  // no stroke written: full guidance
    if (adapts == AdaptiveGuidance::fading) CHECK(none.gain == 1.0);
    if (adapts == AdaptiveGuidance::assist_as_needed) CHECK(none.band_m == schedule.assist_rule.min_band_m);
    if (adapts == AdaptiveGuidance::skill_adaptive) CHECK(none.mode == GuidanceMode::fixed);
    CHECK_REFUSED(InvalidArgument, schedule.next(first, -0.001), "");
    CHECK_REFUSED(InvalidArgument, schedule.next(first, kNaN), "");
    const RepetitionGuidance far = schedule.next(first, 1e308);
    CHECK(far.gain >= 0.0);
    CHECK(far.gain <= 1.0);
    CHECK(std::isfinite(far.band_m));
    RepetitionGuidance copy = far;
    CHECK(copy == far);
    const GuidanceLaw start = adapts == AdaptiveGuidance::fading ? GuidanceLaw{FadingGuidance{}}
                              : adapts == AdaptiveGuidance::assist_as_needed
                                  ? GuidanceLaw{AssistAsNeededGuidance{}}
                                  : GuidanceLaw{FixedGuidance{}};
    const GuidanceLaw law = schedule.law_of(far, start);
    CHECK_NOTHROW(validate_guidance_law(law, 0.006));
  }
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(FadingGuidance{kNaN}, 0.006), "FadingGuidance.gain");
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(AssistAsNeededGuidance{-0.001}, 0.006),
                "AssistAsNeededGuidance.band_m");
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(ErrorAmplificationGuidance{0.25, -1.0}, 0.006),
                "ErrorAmplificationGuidance.max_force_n");
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(TimingGuidance{0.0, 0.003}, 0.006),
                "TimingGuidance.speed_m_s");
  const std::vector<TeacherSample> two{{0.0, Vec3::Zero()}, {0.001, Vec3::Zero()}};
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(ReplayGuidance{two, 0.0}, 0.006),
                "ReplayGuidance.max_lead_m");
  CHECK_REFUSED(InvalidArgument, validate_guidance_law(ReplayGuidance{{}, 0.003}, 0.006), "teacher");
  for (const GuidanceMode mode : guidance_modes()) {
    CHECK(mode_of(default_guidance_law(mode)) == mode);
    CHECK(guidance_mode_from_string(to_string(mode)) == mode);
  }
  CHECK_FALSE(guidance_mode_from_string("Fixed").has_value());
  CHECK_FALSE(guidance_mode_from_string("").has_value());
}

TEST_CASE("unseen12j: the timing target and a teacher's trajectory at their edges", "[unseen12j]") {
  const Scene& scene = scene_of(U'十');
  for (const double speed : {0.0, -0.04, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, TimingTarget(scene, speed), "");
  const TimingTarget target(scene, 0.04);
  CHECK_FALSE(target.empty());
  CHECK(target.duration_s(2) == 0.0);  // past the scene's strokes
  CHECK(target.duration_s(std::size_t(-1)) == 0.0);
  CHECK(target.duration_s(0) > 0.0);
  for (const double elapsed : {-1.0, -0.0, 0.0, 1e308, kInf}) {
    const TimingTarget::Place place = target.place(0, elapsed);
    INFO("elapsed " << elapsed);
    CHECK(place.parameter >= 0.0);
    CHECK(place.parameter <= 1.0);
    CHECK(place.element < scene.characters[0].strokes[0].elements.size());
  }
  const StrokeElement& element = scene.characters[0].strokes[0].elements[0];
  CHECK(target.place(0, -1.0).parameter == 0.0);
  CHECK(target.attraction_point(0, 1e308, 0, element).allFinite());
  CHECK(target.attraction_point(5, 0.1, 0, element).allFinite());  // an index past the end: no crash
  CHECK(TimingTarget().empty());

  std::vector<TeacherSample> teacher{{0.0, Vec3(0, 0, 0)}};
  CHECK_REFUSED(InvalidArgument, validate_teacher_trajectory(teacher), "");
  CHECK_REFUSED(InvalidArgument, validate_teacher_trajectory(std::vector<TeacherSample>{}), "");
  teacher = {{0.0, Vec3::Zero()}, {0.001, Vec3::Zero()}, {0.002, Vec3(kNaN, 0, 0)}, {0.003, Vec3::Zero()}};
  CHECK_REFUSED(InvalidArgument, validate_teacher_trajectory(teacher), "2");
  teacher = {{0.0, Vec3::Zero()}, {0.001, Vec3::Zero()}, {0.002, Vec3::Zero()}, {0.0015, Vec3::Zero()}};
  CHECK_REFUSED(InvalidArgument, validate_teacher_trajectory(teacher), "3");
  teacher = {{0.0, Vec3::Zero()}, {0.0, Vec3::Zero()}};  // equal times are not below: allowed
  CHECK_NOTHROW(validate_teacher_trajectory(teacher));
  // A teacher who rests above the paper wrote no stroke: refused naming the stroke.
  std::vector<TeacherSample> idle;
  for (int i = 0; i < 100; ++i) idle.push_back({i * 1e-3, Vec3(0, 0, 0.02)});
  CHECK_REFUSED(InvalidArgument, TeacherReplay(scene, idle, ForceLawParameters{}), "stroke");
  const TeacherReplay none;
  CHECK(none.empty());
  CHECK(none.position(0, 0.0) == Vec2::Zero());
  CHECK(none.stroke_count() == 0);
}

// ---- analysis
// -------------------------------------------------------------------------------------------------

namespace {
// Every warping path (steps (1,0), (0,1), (1,1)) from (0, 0) to (n-1, m-1), by brute force: the least sum of
// distances with its pair count, and the least largest distance.
struct BruteCurves {
  double dtw_sum = kInf;
  std::size_t dtw_pairs = 0;
  double frechet = kInf;
};
void walk(const std::vector<Vec2>& a, const std::vector<Vec2>& b, std::size_t i, std::size_t j, double sum,
          double largest, std::size_t pairs, BruteCurves& best) {
  const double d = (a[i] - b[j]).norm();
  sum += d;
  largest = std::max(largest, d);
  ++pairs;
  if (i + 1 == a.size() && j + 1 == b.size()) {
    if (sum < best.dtw_sum) best.dtw_sum = sum, best.dtw_pairs = pairs;
    best.frechet = std::min(best.frechet, largest);
    return;
  }
  if (i + 1 < a.size()) walk(a, b, i + 1, j, sum, largest, pairs, best);
  if (j + 1 < b.size()) walk(a, b, i, j + 1, sum, largest, pairs, best);
  if (i + 1 < a.size() && j + 1 < b.size()) walk(a, b, i + 1, j + 1, sum, largest, pairs, best);
}
}  // namespace

TEST_CASE(
    "unseen12j: discrete Frechet and DTW equal a brute force over every warping path, and are symmetric",
    "[unseen12j]") {
  std::mt19937_64 random(2026);
  std::uniform_real_distribution<double> coordinate(-0.01, 0.01);
  std::uniform_int_distribution<std::size_t> length(1, 6);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Vec2> a(length(random)), b(length(random));
    for (Vec2& p : a) p = Vec2(coordinate(random), coordinate(random));
    for (Vec2& p : b) p = Vec2(coordinate(random), coordinate(random));
    BruteCurves best;
    walk(a, b, 0, 0, 0.0, 0.0, 0, best);
    INFO("n " << a.size() << ", m " << b.size());
    CHECK(discrete_frechet_distance(a, b) == best.frechet);
    CHECK(discrete_frechet_distance(b, a) == discrete_frechet_distance(a, b));
    CHECK(dtw_mean_distance(a, b) ==
          Approx(best.dtw_sum / static_cast<double>(best.dtw_pairs)).epsilon(1e-12));
    CHECK(dtw_mean_distance(b, a) == Approx(dtw_mean_distance(a, b)).epsilon(1e-12));
    // The same span on both sides (aliased arguments): 0.
    CHECK(discrete_frechet_distance(a, a) == 0.0);
    CHECK(dtw_mean_distance(a, a) == 0.0);
  }
  // One point each: the distance between them.
  const std::vector<Vec2> p{Vec2(0, 0)}, q{Vec2(0.003, 0.004)};
  CHECK(discrete_frechet_distance(p, q) == Approx(0.005));
  CHECK(dtw_mean_distance(p, q) == Approx(0.005));
}

TEST_CASE(
    "unseen12j: Frechet and DTW refuse an empty or non-finite curve and more than kMaxCurveCells, and answer "
    "at the bound",
    "[unseen12j]") {
  const std::vector<Vec2> none, one{Vec2(0, 0)}, bad{Vec2(0, 0), Vec2(kNaN, 0)},
      huge{Vec2(0, 0), Vec2(kInf, 0)};
  for (auto f : {&discrete_frechet_distance, &dtw_mean_distance}) {
    CHECK_REFUSED(InvalidArgument, f(none, one), "");
    CHECK_REFUSED(InvalidArgument, f(one, none), "");
    CHECK_REFUSED(InvalidArgument, f(none, none), "");
    CHECK_REFUSED(InvalidArgument, f(bad, one), "");
    CHECK_REFUSED(InvalidArgument, f(one, huge), "");
  }
  std::vector<Vec2> a(4096), b(4096), c(4097);
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = Vec2(static_cast<double>(i) * 1e-5, 0.0);
    b[i] = Vec2(static_cast<double>(i) * 1e-5, 0.001);
  }
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = Vec2(static_cast<double>(i) * 1e-5, 0.001);
  CHECK(discrete_frechet_distance(a, b) == Approx(0.001));
  CHECK(dtw_mean_distance(a, b) == Approx(0.001));
  CHECK_REFUSED(InvalidArgument, discrete_frechet_distance(a, c), "");
  CHECK_REFUSED(InvalidArgument, dtw_mean_distance(c, a), "");
  // 1e308 coordinates: their distances overflow; an answer must not be NaN.
  const std::vector<Vec2> far_a{Vec2(-1e308, 0)}, far_b{Vec2(1e308, 0)};
  for (auto f : {&discrete_frechet_distance, &dtw_mean_distance}) {
    const std::string outcome = thrown<InvalidArgument>([&] {
      const double d = f(far_a, far_b);
      if (std::isnan(d)) throw std::runtime_error("NaN distance");
    });
    CHECK((outcome == "[nothing thrown]" || outcome.rfind("[thrown]", 0) == 0));
  }
}

TEST_CASE("unseen12j: resampling and the reference polyline at their edges", "[unseen12j]") {
  const std::vector<Vec2> line{Vec2(0, 0), Vec2(0.01, 0)};
  for (const std::size_t count : {std::size_t(0), std::size_t(1)})
    CHECK_REFUSED(InvalidArgument, resample_by_arc_length(line, count), "");
  CHECK_REFUSED(InvalidArgument, resample_by_arc_length(std::vector<Vec2>{}, 5), "");
  CHECK_REFUSED(InvalidArgument, resample_by_arc_length(std::vector<Vec2>{Vec2(0, 0), Vec2(0, kNaN)}, 5), "");
  const std::vector<Vec2> copies =
      resample_by_arc_length(std::vector<Vec2>{Vec2(1, 2), Vec2(1, 2), Vec2(1, 2)}, 4);
  REQUIRE(copies.size() == 4);
  for (const Vec2& p : copies) CHECK(p == Vec2(1, 2));
  CHECK(resample_by_arc_length(std::vector<Vec2>{Vec2(1, 2)}, 3).size() == 3);
  const std::vector<Vec2> even = resample_by_arc_length(line, 3);
  REQUIRE(even.size() == 3);
  CHECK(even[1].isApprox(Vec2(0.005, 0)));
  CHECK(even.front() == line.front());
  CHECK(even.back() == line.back());
  // A polyline 2e308 long: its length overflows. Points must come out finite, or the call refused.
  const std::string overflow = thrown<InvalidArgument>([&] {
    const std::vector<Vec2> points =
        resample_by_arc_length(std::vector<Vec2>{Vec2(-1e308, 0), Vec2(1e308, 0)}, 5);
    for (const Vec2& p : points)
      if (!p.allFinite()) throw std::runtime_error("a non-finite point");
  });
  CHECK((overflow == "[nothing thrown]" || overflow.rfind("[thrown]", 0) == 0));

  const std::vector<StrokeElement> reference{StrokeElement::line(Vec2(0, 0), Vec2(0.01, 0))};
  for (const double step : {0.0, -0.001, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, reference_polyline_m(reference, step, 100), "");
  CHECK_REFUSED(InvalidArgument, reference_polyline_m(reference, 0.001, 1), "");
  CHECK_REFUSED(InvalidArgument, reference_polyline_m(std::vector<StrokeElement>{}, 0.001, 100), "");
  const std::vector<Vec2> polyline = reference_polyline_m(reference, 0.001, 100);
  CHECK(polyline.size() >= 11);  // 10 mm at steps of at most 1 mm
  CHECK(polyline.size() <= 12);
  CHECK(reference_polyline_m(reference, 1e-9, 50).size() <= 50);
  // A zero-length reference gives points, not NaN.
  const std::vector<Vec2> dot = reference_polyline_m(
      std::vector<StrokeElement>{StrokeElement::line(Vec2(1, 1), Vec2(1, 1))}, 0.001, 100);
  REQUIRE(!dot.empty());
  for (const Vec2& p : dot) CHECK(p == Vec2(1, 1));
}

TEST_CASE(
    "unseen12j: compare_curves: the reference scores at most half a step, a copy 1 mm beside 1 to 1.125 mm",
    "[unseen12j]") {
  const PlacedStroke& stroke = scene_of(U'十').characters[0].strokes[0];
  const std::vector<StrokeElement>& reference = stroke.elements;
  const std::vector<Vec2> itself = reference_polyline_m(reference, 1e-5, 4096);
  const CurveDistances exact = compare_curves(itself, reference);
  CHECK(exact.frechet_m <= 0.125e-3 + 1e-12);
  CHECK(exact.dtw_m <= 0.125e-3 + 1e-12);
  // A copy 1 mm beside it: each point moved 1 mm along the element's normal there.
  std::vector<Vec2> beside;
  for (const StrokeElement& e : reference)
    for (int k = 0; k <= 400; ++k) {
      const Vec2 tangent = e.unit_tangent(k / 400.0);
      beside.push_back(e.point(k / 400.0) + 0.001 * Vec2(-tangent.y(), tangent.x()));
    }
  const CurveDistances shifted = compare_curves(beside, reference);
  CHECK(shifted.frechet_m >= 0.00099);
  CHECK(shifted.frechet_m <= 0.00113);  // 1.125 mm and the chords' error
  // Written backwards and compared with the reference reversed: the same shape.
  const CurveDistances back = compare_curves(reversed(beside), reference, {}, true);
  CHECK(back.frechet_m == Approx(shifted.frechet_m).margin(2e-5));
  // Options out of range, no sample, NaN.
  for (const std::size_t points : {std::size_t(0), std::size_t(1), std::size_t(4097)}) {
    CurveComparisonOptions options;
    options.max_points = points;
    CHECK_REFUSED(InvalidArgument, compare_curves(beside, reference, options), "max_points");
  }
  CurveComparisonOptions nan_step;
  nan_step.reference_step_m = kNaN;
  CHECK_REFUSED(InvalidArgument, compare_curves(beside, reference, nan_step),
                "CurveComparisonOptions.reference_step_m = nan");
  CHECK_REFUSED(InvalidArgument, compare_curves(std::vector<Vec2>{}, reference), "");
  CHECK_REFUSED(InvalidArgument, compare_curves(beside, std::vector<StrokeElement>{}), "");
  CHECK_REFUSED(InvalidArgument, compare_curves(std::vector<Vec2>{Vec2(kNaN, 0)}, reference), "");
  // One sample, and one sample repeated 10^5 times (consecutive repeats dropped): the same distances.
  const std::vector<Vec2> single{stroke.start()};
  const std::vector<Vec2> repeated(100000, stroke.start());
  const CurveDistances one = compare_curves(single, reference);
  const CurveDistances many = compare_curves(repeated, reference);
  CHECK(one.frechet_m == many.frechet_m);
  CHECK(one.dtw_m == Approx(many.dtw_m));
  CHECK(one.frechet_m >= (stroke.end() - stroke.start()).norm() - 1e-9);  // the end is a reference point
}

TEST_CASE(
    "unseen12j: stroke kinematics refuse what they document and give sqrt(360) for a minimum-jerk stroke",
    "[unseen12j]") {
  const std::vector<double> t2{0.0, 0.1};
  const std::vector<Vec2> p2{Vec2(0, 0), Vec2(0.01, 0)};
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(std::vector<double>{0.0}, std::vector<Vec2>{Vec2(0, 0)}),
                "");
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(std::vector<double>{0.0, 0.1, 0.2}, p2), "");
  CHECK_REFUSED(InvalidArgument,
                stroke_kinematics(std::vector<double>{0.0, 0.1, 0.05, 0.2},
                                  std::vector<Vec2>{Vec2(0, 0), Vec2(1e-3, 0), Vec2(2e-3, 0), Vec2(3e-3, 0)}),
                "2");
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(std::vector<double>{0.0, 0.0}, p2), "");  // T = 0
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(t2, std::vector<Vec2>{Vec2(1, 1), Vec2(1, 1)}),
                "");  // L = 0
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(std::vector<double>{0.0, kNaN}, p2), "");
  CHECK_REFUSED(InvalidArgument, stroke_kinematics(t2, std::vector<Vec2>{Vec2(0, 0), Vec2(kInf, 0)}), "");
  const auto refused_option = [&](auto set, const char* field) {
    KinematicsOptions options;
    set(options);
    CHECK_REFUSED(InvalidArgument, stroke_kinematics(t2, p2, options), field);
  };
  refused_option([](KinematicsOptions& o) { o.low_pass_cutoff_hz = -1.0; },
                 "KinematicsOptions.low_pass_cutoff_hz = -1");
  refused_option([](KinematicsOptions& o) { o.low_pass_cutoff_hz = kNaN; },
                 "KinematicsOptions.low_pass_cutoff_hz = nan");
  refused_option([](KinematicsOptions& o) { o.peak_prominence = 0.0; },
                 "KinematicsOptions.peak_prominence = 0");
  refused_option([](KinematicsOptions& o) { o.peak_prominence = 1.0; },
                 "KinematicsOptions.peak_prominence = 1");
  refused_option([](KinematicsOptions& o) { o.max_grid_points = 15; }, "max_grid_points");
  // A minimum-jerk movement of 30 mm in 0.6 s at 1 kHz, unfiltered: 18.91 (docs/metrics.md), one peak.
  std::vector<double> times;
  std::vector<Vec2> positions;
  for (int i = 0; i <= 600; ++i) {
    const double u = i / 600.0;
    times.push_back(i * 1e-3);
    positions.emplace_back(0.03 * (10 * std::pow(u, 3) - 15 * std::pow(u, 4) + 6 * std::pow(u, 5)), 0.0);
  }
  KinematicsOptions unfiltered;
  unfiltered.low_pass_cutoff_hz = 0.0;
  const StrokeKinematics k = stroke_kinematics(times, positions, unfiltered);
  CHECK(k.normalised_jerk == Approx(18.91).margin(0.05));
  CHECK(k.velocity_peaks == 1);
  CHECK(k.writing_time_s == Approx(0.6));
  CHECK(k.path_length_m == Approx(0.03));
  CHECK(k.mean_speed_m_per_s == Approx(0.05));
  // 10^6 samples: bounded by max_grid_points, answered.
  std::vector<double> long_times(1000000);
  std::vector<Vec2> long_positions(1000000);
  for (std::size_t i = 0; i < long_times.size(); ++i) {
    long_times[i] = static_cast<double>(i) * 1e-3;
    long_positions[i] = Vec2(1e-5 * static_cast<double>(i), 0.0);
  }
  const StrokeKinematics long_stroke = stroke_kinematics(long_times, long_positions);
  CHECK(std::isfinite(long_stroke.normalised_jerk));
  CHECK(long_stroke.mean_speed_m_per_s == Approx(0.01));
}

TEST_CASE(
    "unseen12j: deviation pools refuse bad values, merge with themselves and pool summaries as documented",
    "[unseen12j]") {
  CHECK_REFUSED(InvalidArgument, DeviationPool(-0.001), "");
  CHECK_REFUSED(InvalidArgument, DeviationPool(kNaN), "");
  CHECK_REFUSED(InvalidArgument, DeviationPool(kInf), "");
  DeviationPool pool(0.002);
  CHECK_REFUSED(InvalidArgument, pool.summary(), "");
  for (const double bad : {-1e-9, kNaN, kInf}) CHECK_REFUSED(InvalidArgument, pool.add(bad), "");
  CHECK(pool.samples() == 0);
  for (const double d : {0.001, 0.003, -0.0, kDenormal}) pool.add(d);
  const DeviationSummary before = pool.summary();
  pool.merge(pool);  // aliased: every sample once more
  const DeviationSummary after = pool.summary();
  CHECK(after.samples == 2 * before.samples);
  CHECK(after.mean_m == Approx(before.mean_m));
  CHECK(after.rms_m == Approx(before.rms_m));
  CHECK(after.max_m == before.max_m);
  CHECK(after.outside_tube_share == Approx(0.25));
  DeviationPool other(0.003);
  other.add(0.001);
  CHECK_REFUSED(InvalidArgument, pool.merge(other), "");
  CHECK_REFUSED(InvalidArgument, pool_deviation_summaries(std::span<const DeviationSummary>{}), "");
  DeviationSummary empty_part = before;
  empty_part.samples = 0;
  const std::vector<DeviationSummary> with_empty{before, empty_part};
  CHECK_REFUSED(InvalidArgument, pool_deviation_summaries(with_empty), "");
  DeviationSummary other_radius = before;
  other_radius.tube_radius_m = 0.001;
  const std::vector<DeviationSummary> mixed{before, other_radius};
  CHECK_REFUSED(InvalidArgument, pool_deviation_summaries(mixed), "");
  const std::vector<DeviationSummary> twice{before, before};
  const DeviationSummary pooled = pool_deviation_summaries(twice);
  CHECK(pooled.samples == after.samples);
  CHECK(pooled.mean_m == Approx(after.mean_m));
  CHECK(pooled.rms_m == Approx(after.rms_m));
  const std::vector<StrokeElement> reference{StrokeElement::line(Vec2(0, 0), Vec2(0.01, 0))};
  CHECK_REFUSED(InvalidArgument, deviation_from_stroke_m(std::span<const StrokeElement>{}, Vec2(0, 0)), "");
  CHECK_REFUSED(InvalidArgument, deviation_from_stroke_m(reference, Vec2(kNaN, 0)), "");
  CHECK_REFUSED(InvalidArgument, deviation_summary(std::vector<Vec2>{}, reference, 0.002), "");
  CHECK_REFUSED(InvalidArgument, deviation_summary(std::vector<Vec2>{Vec2(0, 0)}, reference, -1.0), "");
  const DeviationSummary zero_tube =
      deviation_summary(std::vector<Vec2>{Vec2(0.005, 0), Vec2(0.005, 0.001)}, reference, 0.0);
  CHECK(zero_tube.outside_tube_share == Approx(0.5));
  CHECK(zero_tube.mean_m == Approx(0.0005));
}

TEST_CASE(
    "unseen12j: match_stroke on the median, the median reversed, one point, NaN, no point and a bad radius",
    "[unseen12j]") {
  const PlacedCharacter& cross = scene_of(U'十').characters[0];
  const double radius = SceneLayout{}.start_radius_m;
  for (std::size_t s = 0; s < cross.strokes.size(); ++s) {
    const std::vector<Vec2>& median = cross.strokes[s].median_m;
    INFO("stroke " << s);
    const StrokeMatch forwards = match_stroke(cross, s, median, radius);
    CHECK(forwards.accepted);
    CHECK(forwards.refusal == StrokeRefusal::none);
    CHECK(forwards.covered_fraction >= 0.0);
    CHECK(forwards.covered_fraction <= 1.0);
    const StrokeMatch back = match_stroke(cross, s, reversed(median), radius);
    CHECK_FALSE(back.accepted);
    CHECK(back.refusal == StrokeRefusal::backwards);
    CHECK(back.covered_fraction >= 0.0);
    CHECK(back.covered_fraction <= 1.0);
    for (const Vec2& point : {cross.strokes[s].start(), cross.strokes[s].end(), Vec2(5.0, 5.0)}) {
      const StrokeMatch single = match_stroke(cross, s, std::vector<Vec2>{point}, radius);
      CHECK_FALSE(single.accepted);
      CHECK(single.refusal != StrokeRefusal::none);
      CHECK(std::isfinite(single.mean_deviation_m));
    }
  }
  // The second stroke first: written out of turn.
  const StrokeMatch early = match_stroke(cross, 0, cross.strokes[1].median_m, radius);
  CHECK_FALSE(early.accepted);
  CHECK(early.refusal == StrokeRefusal::wrong_order);
  CHECK(early.matched_stroke == 1);
  const std::vector<Vec2> all_nan(50, Vec2(kNaN, kNaN));
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, 0, all_nan, radius), "");
  std::vector<Vec2> one_nan = cross.strokes[0].median_m;
  one_nan[1].y() = kNaN;
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, 0, one_nan, radius), "");
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, 0, std::vector<Vec2>{}, radius), "");
  for (const double bad : {0.0, -0.005, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, match_stroke(cross, 0, cross.strokes[0].median_m, bad), "");
  StrokeAcceptance invalid;
  invalid.corridor_m = 0.0;
  CHECK_REFUSED(InvalidArgument, match_stroke(cross, 0, cross.strokes[0].median_m, radius, invalid),
                "corridor_m");
  // A stroke not placed by Scene::lay_out (no centre line), and one without elements.
  PlacedStroke bare = cross.strokes[0];
  bare.centre_line = StrokeCentreLine{};
  CHECK_REFUSED(InvalidArgument, attempt_stroke(bare, cross.strokes[0].median_m, radius), "");
  PlacedStroke hollow = cross.strokes[0];
  hollow.elements.clear();
  CHECK_REFUSED(InvalidArgument, attempt_stroke(hollow, cross.strokes[0].median_m, radius), "");
}

TEST_CASE("unseen12j: match_stroke on a million points of the median gives the same verdict as the median",
          "[unseen12j]") {
  const PlacedCharacter& hook = scene_of(U'乙').characters[0];
  const std::vector<Vec2>& median = hook.strokes[0].median_m;
  const double length = polyline_length(median);
  std::vector<Vec2> dense = resample(median, length / 1000010.0);
  REQUIRE(dense.size() >= 1000000);
  const StrokeMatch coarse = match_stroke(hook, 0, median, SceneLayout{}.start_radius_m);
  const StrokeMatch fine = match_stroke(hook, 0, dense, SceneLayout{}.start_radius_m);
  CHECK(coarse.accepted);
  CHECK(fine.accepted == coarse.accepted);
  CHECK(fine.covered_fraction == Approx(coarse.covered_fraction).margin(0.01));
  CHECK(fine.mean_deviation_m == Approx(coarse.mean_deviation_m).margin(1e-4));
}

TEST_CASE(
    "unseen12j: scoring empty, one-sample, backwards and many-segment traces, and times to the nanosecond",
    "[unseen12j]") {
  const Scene& scene = scene_of(U'十');
  const PlacedCharacter& cross = scene.characters[0];
  const CharacterScore nothing = score_trace(cross, std::vector<PenSample>{});
  CHECK(nothing.strokes_written == 0);
  CHECK(nothing.missing_strokes == std::vector<std::size_t>{0, 1});
  CHECK(nothing.segments.empty());
  CHECK_FALSE(nothing.strokes_in_order);
  CHECK_FALSE(nothing.totals.deviation.has_value());
  CHECK_FALSE(nothing.totals.total_time_s.has_value());  // no pen-down sample: no time from first to last
  const std::vector<PenSample> one{{0.5, cross.strokes[0].start(), true}};
  const CharacterScore single = score_trace(cross, one);
  REQUIRE(single.segments.size() == 1);
  CHECK(single.segments[0].ignored);
  CHECK(single.ignored_segments == 1);
  CHECK(single.strokes_written == 0);
  std::vector<PenSample> backwards_in_time = pen_down_samples(densely(cross.strokes[0].median_m, 1e-4));
  backwards_in_time[2].time_s = -1.0;
  CHECK_REFUSED(InvalidArgument, score_trace(cross, backwards_in_time), "2");
  std::vector<PenSample> nan_sample = pen_down_samples(densely(cross.strokes[0].median_m, 1e-4));
  nan_sample[1].position_m.x() = kNaN;
  CHECK_REFUSED(InvalidArgument, score_trace(cross, nan_sample), "1");
  CHECK_REFUSED(InvalidArgument, validate_pen_trace(nan_sample), "1");
  ScoreOptions radius;
  radius.start_radius_m = 0.0;
  CHECK_REFUSED(InvalidArgument, score_trace(cross, one, radius), "start_radius_m");
  ScoreOptions segments;
  segments.max_segments = 0;
  CHECK_REFUSED(InvalidArgument, score_trace(cross, one, segments), "max_segments");
  // 10,001 pen-down segments: refused before matching.
  std::vector<PenSample> taps;
  for (int i = 0; i < 10001; ++i) {
    taps.push_back({i * 2e-3, cross.strokes[0].start(), true});
    taps.push_back({i * 2e-3 + 1e-3, cross.strokes[0].start(), false});
  }
  CHECK_REFUSED(InvalidArgument, score_trace(cross, taps), "10000");
  // Pen down from 0.002 s to 13.075 s: 13.073 s, not 13.072999999999999.
  std::vector<PenSample> slow;
  const std::vector<Vec2> path = densely(cross.strokes[0].median_m, 1e-5);
  for (int i = 2; i <= 13075; ++i) {
    const std::size_t k = std::min(path.size() - 1, static_cast<std::size_t>(i - 2) * path.size() / 13074);
    slow.push_back({i * 1e-3, path[k], true});
  }
  slow.front().time_s = 0.002;
  slow.back().time_s = 13.075;
  const WritingMetrics metrics = writing_metrics(scene, slow);
  CHECK(metrics.total_time_s == 13.073);
  CHECK(metrics.pen_down_time_s == 13.073);
  CHECK(metrics.strokes_written == 1);
  // All pen up: nothing written, nothing refused.
  std::vector<PenSample> hovering = pen_down_samples(densely(cross.strokes[0].median_m, 1e-4));
  for (PenSample& s : hovering) s.pen_down = false;
  const WritingMetrics up = writing_metrics(scene, hovering);
  CHECK(up.strokes_written == 0);
  CHECK(up.refusals.total() == 0);
  CHECK_FALSE(up.deviation.has_value());
}

TEST_CASE(
    "unseen12j: the quiz refuses bad options and samples by index, accepts the medians and ignores what "
    "follows",
    "[unseen12j]") {
  const PlacedCharacter& cross = scene_of(U'十').characters[0];
  QuizOptions radius;
  radius.start_radius_m = kNaN;
  CHECK_REFUSED(InvalidArgument, QuizSession(cross, radius), "start_radius_m");
  for (const int hint : {-1, 1001}) {
    QuizOptions options;
    options.hint_after_misses = hint;
    CHECK_REFUSED(InvalidArgument, QuizSession(cross, options), "hint_after_misses");
  }
  QuizSession quiz(cross);
  CHECK(quiz.feed({0.0, Vec2(0, 0), false}).empty());
  CHECK_REFUSED(InvalidArgument, quiz.feed({kNaN, Vec2(0, 0), false}), "1");
  CHECK_REFUSED(InvalidArgument, quiz.feed({-1.0, Vec2(0, 0), false}), "1");
  double t = 0.001;
  std::vector<QuizEvent> events;
  for (std::size_t s = 0; s < cross.strokes.size(); ++s) {
    for (const Vec2& p : densely(cross.strokes[s].median_m, 2e-4)) {
      for (const QuizEvent& e : quiz.feed({t, p, true})) events.push_back(e);
      t += 1e-3;
    }
    for (const QuizEvent& e : quiz.feed({t, cross.strokes[s].end(), false})) events.push_back(e);
    t += 1e-3;
  }
  CHECK(quiz.complete());
  REQUIRE(events.size() == 3);
  CHECK(events[0].kind == QuizEvent::Kind::stroke_accepted);
  CHECK(events[1].kind == QuizEvent::Kind::stroke_accepted);
  CHECK(events[2].kind == QuizEvent::Kind::character_completed);
  // After the character is complete, samples are ignored.
  CHECK(quiz.feed({t, cross.strokes[0].start(), true}).empty());
  CHECK(quiz.feed({t + 1.0, cross.strokes[0].end(), true}).empty());
  CHECK(quiz.finish().empty());
  CHECK(quiz.events().size() == 3);
  CHECK(std::string(to_string(QuizEvent::Kind::too_short)) == "too_short");
  // A hint after the override's count of misses, and after each further one.
  QuizOptions hinting;
  hinting.hint_after_misses = 1;
  QuizSession misses(cross, hinting);
  t = 0.0;
  int hints = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    for (const Vec2& p : densely(reversed(cross.strokes[0].median_m), 2e-4))
      for (const QuizEvent& e : misses.feed({t += 1e-3, p, true})) hints += e.kind == QuizEvent::Kind::hint;
    for (const QuizEvent& e : misses.feed({t += 1e-3, cross.strokes[0].start(), false}))
      hints += e.kind == QuizEvent::Kind::hint;
  }
  CHECK(misses.misses_on_stroke() == 3);
  CHECK(hints == 3);
}

TEST_CASE(
    "unseen12j: the metric table: one name each, legacy names found, unknown names refused by name, rows "
    "copied",
    "[unseen12j]") {
  std::vector<std::string_view> names;
  for (const MetricInfo& info : metric_table()) {
    names.push_back(info.name);
    CHECK(info.levels != 0);
    if (!info.legacy_name.empty()) {
      const auto legacy = find_metric(info.legacy_name);
      REQUIRE(legacy.has_value());
      CHECK(legacy->name == info.name);
    }
  }
  std::sort(names.begin(), names.end());
  CHECK(std::adjacent_find(names.begin(), names.end()) == names.end());
  CHECK(find_metric("mean_deviation_mm")->name == "mean_deviation_m");
  CHECK_FALSE(find_metric("").has_value());
  CHECK_FALSE(find_metric("MEAN_DEVIATION_M").has_value());
  CHECK_REFUSED(InvalidArgument, metric("no_such_metric"), "no_such_metric");
  MetricValues row(StudyTable::trials);
  CHECK_REFUSED(InvalidArgument, row.at("no_such_metric"), "no_such_metric");
  CHECK_REFUSED(InvalidArgument, row.set("no_such_metric", 1.0), "no_such_metric");
  CHECK_REFUSED(InvalidArgument, row.number(""), "");
  CHECK_FALSE(row.number("mean_deviation_m").has_value());
  row.set("mean_deviation_m", 0.001);
  MetricValues copy = row;
  CHECK(copy.number("mean_deviation_m") == 0.001);
  MetricValues moved = std::move(row);
  CHECK(moved.number("mean_deviation_m") == 0.001);
  row = copy;  // a moved-from row takes a new value
  CHECK(row.number("mean_deviation_m") == 0.001);
  CHECK(row.names().size() == row.values().size());
  CHECK(metric_levels_text(static_cast<std::uint8_t>(metric_level_scene | metric_level_stroke)) ==
        "scene, stroke");
  const nlohmann::json schema = nlohmann::json::parse(metric_json_schema(metric_level_scene));
  CHECK(schema.is_object());
}

// ---- trial and report
// ------------------------------------------------------------------------------------------

TEST_CASE(
    "unseen12j: a teacher's recording round-trips -0, denormals and 1e308 exactly and refuses bad files by "
    "key",
    "[unseen12j]") {
  TeacherRecording recording;
  recording.characters = "十";
  recording.writer = "human";
  recording.device = "simulated";
  recording.rate_hz = 1000.0;
  recording.samples = {{0.0, Vec3(-0.0, kDenormal, -kDenormal)},
                       {kDenormal, Vec3(1e308, -1e308, 0.1)},
                       {1e308, Vec3(std::nextafter(0.0, 1.0), 0.30000000000000004, -0.0)}};
  const TeacherRecording back = parse_teacher_recording(teacher_recording_json(recording), "r.json");
  REQUIRE(back.samples.size() == recording.samples.size());
  for (std::size_t i = 0; i < back.samples.size(); ++i) {
    CHECK(back.samples[i] == recording.samples[i]);
    for (int c = 0; c < 3; ++c)
      CHECK(std::signbit(back.samples[i].position_m[c]) == std::signbit(recording.samples[i].position_m[c]));
  }
  CHECK(back.characters == "十");
  const auto document = [](const std::string& samples,
                           const std::string& head =
                               R"("format": "calligraphy-teacher-recording", "version": 1)") {
    return "{" + head +
           R"(, "characters": "十", "writer": "human", "device": "simulated", "rate_hz": 1000, "library_version": "", "samples": )" +
           samples + "}";
  };
  CHECK_NOTHROW(parse_teacher_recording(
      document(R"({"t_s": [0, 1], "x_m": [0, 0], "y_m": [0, 0], "z_m": [0, 0]})"), "ok.json"));
  CHECK_REFUSED(
      DataError,
      parse_teacher_recording(document(R"({"t_s": [0], "x_m": [0], "y_m": [0], "z_m": [0]})"), "r.json"),
      "r.json");
  CHECK_REFUSED(DataError,
                parse_teacher_recording(
                    document(R"({"t_s": [0, 1], "x_m": [0], "y_m": [0, 0], "z_m": [0, 0]})"), "r.json"),
                "samples");
  CHECK_REFUSED(DataError,
                parse_teacher_recording(
                    document(R"({"t_s": [0, 1, 0.5], "x_m": [0, 0, 0], "y_m": [0, 0, 0], "z_m": [0, 0, 0]})"),
                    "r.json"),
                "2");
  CHECK_REFUSED(
      DataError,
      parse_teacher_recording(document(R"({"t_s": [0, 1], "x_m": [0, 1e400], "y_m": [0, 0], "z_m": [0, 0]})"),
                              "r.json"),
      "x_m");
  CHECK_REFUSED(
      DataError,
      parse_teacher_recording(document(R"({"t_s": [0, 1], "x_m": [0, 0], "y_m": [0, 0], "z_m": [0, 0]})",
                                       R"("format": "calligraphy-teacher-recording", "version": 2)"),
                              "r.json"),
      "version");
  CHECK_REFUSED(
      DataError,
      parse_teacher_recording(document(R"({"t_s": [0, 1], "x_m": [0, 0], "y_m": [0, 0], "z_m": [0, 0]})",
                                       R"("format": "other", "version": 1)"),
                              "r.json"),
      "format");
  CHECK_REFUSED(DataError, parse_teacher_recording("", "blank.json"), "blank.json");
  CHECK_REFUSED(InvalidArgument, teacher_recording_from_trace("十", "human", "simulated", 1000.0, {}), "");
  CHECK_REFUSED(InvalidArgument,
                teacher_recording_from_trace("十", "human", "simulated", 1000.0, std::vector<TrialSample>(1)),
                "");
  CHECK_REFUSED(InvalidArgument, require_teacher_for(recording, "口"), "口");
  CHECK_NOTHROW(require_teacher_for(recording, "十"));
}

TEST_CASE(
    "unseen12j: the reports of an empty metrics record and of a character of no strokes are whole and say "
    "nothing is there",
    "[unseen12j]") {
  const WritingMetrics empty;
  const nlohmann::json record = nlohmann::json::parse(writing_metrics_json(empty));
  CHECK(record.at("mean_deviation_m").is_null());
  CHECK(record.at("frechet_m").is_null());
  CHECK(record.at("per_character").empty());
  CHECK(record.at("strokes_total") == 0);
  CHECK_NOTHROW(score_table(ScoreDescription{}, empty));
  const nlohmann::json score = nlohmann::json::parse(score_json(ScoreDescription{}, empty));
  CHECK(score.contains("samples"));
  // A scene's metrics where nothing was written: every value is null or zero, never NaN.
  const WritingMetrics nothing = writing_metrics(scene_of(U'十'), std::vector<PenSample>{});
  const std::string text = writing_metrics_json(nothing);
  CHECK(text.find("nan") == std::string::npos);
  CHECK(text.find("NaN") == std::string::npos);
  const nlohmann::json parsed = nlohmann::json::parse(text);
  CHECK(parsed.at("per_character").size() == 1);
  CHECK(parsed.at("per_character")[0].at("missing_strokes").size() == 2);
  const std::string table = score_table(ScoreDescription{"十", "none.csv", "m", 0}, nothing);
  CHECK(table.find("nan") == std::string::npos);
  CHECK(table.find("not written") != std::string::npos);

  Character hollow;
  hollow.code_point = U'十';
  hollow.source = "test";
  for (const auto& render : {std::function<std::string(const Character&)>(model_json),
                             std::function<std::string(const Character&)>(model_text),
                             std::function<std::string(const Character&)>(model_svg)}) {
    const std::string outcome = thrown<InvalidArgument>([&] { static_cast<void>(render(hollow)); });
    CHECK((outcome == "[nothing thrown]" || outcome.rfind("[thrown]", 0) == 0));
  }
  if (thrown<InvalidArgument>([&] { static_cast<void>(model_json(hollow)); }) == "[nothing thrown]") {
    const nlohmann::json model = nlohmann::json::parse(model_json(hollow));
    CHECK(model.at("strokes").empty());
  }
  Character odd = embedded_character(U'十');
  odd.strokes[0].elements[0].degree = 0;
  CHECK_REFUSED(InvalidArgument, model_json(odd), "");
}

TEST_CASE(
    "unseen12j: the study pages with no session, no trial, hostile text and a trial that wrote no stroke",
    "[unseen12j]") {
  StudyReportIndex index;
  index.title = "<script>alert(1)</script> & \"study\"";
  index.notes = {"<b>note</b>"};
  const std::string page = study_index_html(index, "report.html");
  CHECK(page.find("<script>") == std::string::npos);
  CHECK(page.find("<b>note") == std::string::npos);
  CHECK(page.find("&lt;script&gt;") != std::string::npos);
  CHECK(session_pages_folder("report.html") == "report_files");
  CHECK(session_page_path("report", "S01", "day1") == "report_files/S01/day1.html");
  CHECK(trial_anchor("day1", 3) == "trial-day1-3");

  ReportSession session;
  session.subject = "S01";
  session.session = "s<1>";
  SessionPageHtml empty_page(session, "t", "../../report.html");
  CHECK(empty_page.trials() == 0);
  const std::string empty_html = empty_page.finish();
  CHECK(empty_html.find("s<1>") == std::string::npos);

  SessionPageHtml page_of_one(session, "t", "../../report.html");
  ReportTrial trial;
  trial.subject = "S01";
  trial.session = "s1";
  trial.characters = "十";
  trial.mean_deviation_m = kNaN;  // wrote no stroke
  trial.reference_m = {std::vector<Vec2>{Vec2(0, 0), Vec2(0.01, 0)}};
  trial.stroke_starts_m = {Vec2(0, 0)};
  page_of_one.add(trial);  // no trace at all
  ReportTrial one_tick = trial;
  one_tick.index = 2;
  one_tick.time_s = {0.0};
  one_tick.position_m = {Vec2(0, 0)};
  one_tick.pen_down = {true};
  one_tick.in_plane_force_n = {0.0};
  page_of_one.add(one_tick);
  CHECK(page_of_one.trials() == 2);
  const std::string html = page_of_one.finish();
  CHECK(html.find("trial-s1-1") != std::string::npos);
  CHECK(html.find("trial-s1-2") != std::string::npos);
  for (const char* bad : {">nan", " nan", "NaN", ">inf", " inf "}) {
    INFO(bad);
    CHECK(html.find(bad) == std::string::npos);
  }
}

// ---- study
// ----------------------------------------------------------------------------------------------------

TEST_CASE("unseen12j: an empty study: no session folder refused by name, empty tables, no subject's record",
          "[unseen12j]") {
  TempFolder folder;
  CHECK_REFUSED(DataError, read_study_tables({folder.path}), folder.path.string());
  CHECK_REFUSED(DataError, read_study_tables({folder.path / "missing"}), "missing");
  const StudyTables none;
  const std::string trials = trials_csv(none);
  const std::string strokes = strokes_csv(none);
  CHECK(std::count(trials.begin(), trials.end(), '\n') <= 1);
  CHECK(trials.find("subject") != std::string::npos);
  CHECK(trials.find("mean_deviation_m") != std::string::npos);
  CHECK(std::count(strokes.begin(), strokes.end(), '\n') <= 1);
  CHECK(strokes.find("typical_id") != std::string::npos);
  CHECK_REFUSED(InvalidArgument, typical_stroke_record(none, "S01"), "S01");
  CHECK(written_characters(none, "S01").empty());
  const std::string roots_outcome = thrown<Error>([&] {
    const StudyTables tables = read_study_tables({});
    if (!tables.trials.empty()) throw std::runtime_error("rows from no folder");
  });
  CHECK((roots_outcome == "[nothing thrown]" || roots_outcome.rfind("[thrown]", 0) == 0));
}

TEST_CASE(
    "unseen12j: planning from a constant outcome proposes no weak stroke, and choices of none or too many "
    "are clear",
    "[unseen12j]") {
  const auto ids = [](char32_t c) {
    std::vector<int> out;
    for (const Stroke& s : embedded_character(c).strokes) out.push_back(s.typical_id);
    return out;
  };
  // Every typical stroke written with the same deviation: none is above the median, so none is weak.
  std::vector<TypicalStrokeRecord> constant;
  for (const int id : ids(U'十')) constant.push_back({id, 4, 0.001});
  for (const int id : ids(U'口')) constant.push_back({id, 4, 0.001});
  const std::vector<ProposedCharacter> proposed =
      propose_characters(constant, U"十口", U"日人大山十", 3, ids);
  for (const ProposedCharacter& p : proposed) {
    CHECK(p.weak_strokes.empty());
    CHECK(p.character != U'十');  // written: never proposed
    CHECK_FALSE(p.new_strokes.empty());
  }
  CHECK(propose_characters(constant, U"十口", U"日人大", 0, ids).empty());
  CHECK(propose_characters({}, U"", U"", 5, ids).empty());
  const std::vector<ProposedCharacter> fresh = propose_characters({}, U"", U"人", 5, ids);
  REQUIRE(fresh.size() == 1);
  CHECK(fresh[0].new_strokes.size() >= 1);
  CHECK(choose_transfer_characters(U"十口", U"日", 0, ids).empty());
  CHECK_REFUSED(InvalidArgument, choose_transfer_characters(U"十口", U"人大", 1, ids), "0");
  CHECK_REFUSED(InvalidArgument, choose_transfer_characters(U"十", U"十", 1, ids), "");
}

TEST_CASE("unseen12j: cohorts of no, one and too many subjects, and the guidance shares at their edges",
          "[unseen12j]") {
  CHECK_REFUSED(InvalidArgument, numbered_subjects(0), "");
  CHECK_REFUSED(InvalidArgument, numbered_subjects(kMaxCohortSubjects + 1), "");
  CHECK_REFUSED(InvalidArgument, numbered_subjects(1, "../"), "");
  const std::vector<SubjectAssignment> one = numbered_subjects(1);
  REQUIRE(one.size() == 1);
  CHECK(one[0].id == "S01");
  CHECK(one[0].number == 1);
  CHECK(numbered_subjects(100).back().id == "S100");
  const LoadedProtocol protocol = protocol_from_text(R"({
    "format": "calligraphy-study-protocol", "version": 1, "name": "tiny",
    "conditions": [{"name": "vision", "mode": "vision"}],
    "test": {"characters": ["十"], "conditions": ["vision"], "repetitions": 1},
    "trial": {"max_duration_s": 0.5, "rate_hz": 1000}
  })",
                                                     "tiny.json");
  CohortSetup setup;
  setup.writer_learning = WriterLearning::none;
  setup.individual_differences = false;
  setup.load_character = [](char32_t c) { return embedded_character(c); };
  CHECK_REFUSED(InvalidArgument, simulate_cohort(protocol, one, setup, 0), "");
  const std::string no_subjects = thrown<InvalidArgument>([&] {
    const StudyTables tables = simulate_cohort(protocol, {}, setup, 1);
    if (!tables.trials.empty()) throw std::runtime_error("rows of no subject");
  });
  CHECK((no_subjects == "[nothing thrown]" || no_subjects.rfind("[thrown]", 0) == 0));
  const StudyTables tables = simulate_cohort(protocol, one, setup, 1);
  REQUIRE(tables.trials.size() == 1);
  CHECK(tables.trials[0].subject == "S01");
  CHECK(tables.trials[0].characters == "十");
  CHECK(tables.strokes.size() == 2);
  CohortSetup unknown = setup;
  unknown.writer_profile = "expert";
  CHECK_REFUSED(InvalidArgument, simulate_cohort(protocol, one, unknown, 1), "writer_profile");

  const ForceLawParameters force;
  for (const double k : {0.0, -1.0, kNaN, kInf})
    CHECK_REFUSED(InvalidArgument, guidance_shares(force, k, 0.001), "");
  CHECK_REFUSED(InvalidArgument, guidance_shares(force, 150.0, -1e-9), "");
  for (const GuidanceMode mode : guidance_modes()) {
    ForceLawParameters law;
    law.guidance_law = default_guidance_law(mode);
    if (auto* replay =
            std::get_if<ReplayGuidance>(&law.guidance_law))  // a replay is checked with its teacher
      replay->teacher_trajectory = {{0.0, Vec3::Zero()}, {0.001, Vec3::Zero()}};
    for (const double deviation : {kNaN, 0.0, 1e-9, 0.001, 1e308}) {
      const AssistanceShares shares = guidance_shares(law, 150.0, deviation);
      INFO(to_string(mode) << ", deviation " << deviation);
      for (const double share : {shares.shape, shares.timing, shares.timing_demonstration}) {
        REQUIRE(std::isfinite(share));
        CHECK(share <= 1.0);
      }
      // Only error amplification takes a negative share of the shape (it enlarges the error).
      if (mode != GuidanceMode::error_amplification) CHECK(shares.shape >= 0.0);
      CHECK(shares.timing >= 0.0);
      CHECK(shares.timing_demonstration >= 0.0);
    }
  }
  ForceLawParameters off;
  off.guidance = false;
  CHECK(guidance_shares(off, 150.0, 0.001).shape == 0.0);
}
