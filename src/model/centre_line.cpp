#include <algorithm>
#include <limits>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {
namespace {

// Points per element when a stroke has no median: dense enough that the chord error of a Bezier element
// stays far below the acceptance tolerances (a quarter circle of 20 mm sampled at 16 points: 0.02 mm).
constexpr int kSamplesPerElement = 16;

std::vector<Vec2> sampled_elements(const std::vector<StrokeElement>& elements) {
  std::vector<Vec2> points;
  for (const StrokeElement& e : elements) {
    const int samples = e.degree == 1 ? 1 : kSamplesPerElement;
    if (points.empty()) points.push_back(e.start());
    for (int i = 1; i <= samples; ++i) points.push_back(e.point(static_cast<double>(i) / samples));
  }
  return points;
}

// Arc of the point of the polyline nearest to p among the part at arc >= from_arc.
double project(const StrokeCentreLine& line, const Vec2& p, double from_arc) {
  double best_distance = std::numeric_limits<double>::infinity();
  double best_arc = from_arc;
  for (std::size_t k = 1; k < line.points_m.size(); ++k) {
    if (line.arc_m[k] < from_arc) continue;
    const Vec2& a = line.points_m[k - 1];
    const Vec2& b = line.points_m[k];
    const double segment = line.arc_m[k] - line.arc_m[k - 1];
    const double t_min = segment > 0.0 ? std::clamp((from_arc - line.arc_m[k - 1]) / segment, 0.0, 1.0) : 0.0;
    const double t = std::max(t_min, segment_parameter(a, b, p));
    const double distance = (a + t * (b - a) - p).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best_arc = line.arc_m[k - 1] + t * segment;
    }
  }
  return best_arc;
}

}  // namespace

StrokeCentreLine StrokeCentreLine::of(const std::vector<Vec2>& median,
                                      const std::vector<StrokeElement>& elements) {
  if (elements.empty()) throw InvalidArgument("StrokeCentreLine: a stroke without elements");
  StrokeCentreLine line;
  for (const Vec2& p : median.size() >= 2 ? median : sampled_elements(elements)) {
    if (line.points_m.empty() || p != line.points_m.back()) line.points_m.push_back(p);
  }
  if (line.points_m.size() < 2) line.points_m = sampled_elements(elements);
  if (line.points_m.size() < 2) line.points_m.push_back(line.points_m.front());  // a zero-length stroke
  line.arc_m.push_back(0.0);
  for (std::size_t k = 1; k < line.points_m.size(); ++k)
    line.arc_m.push_back(line.arc_m.back() + (line.points_m[k] - line.points_m[k - 1]).norm());
  // Feature points projected in order: each at or after the last, so the corners keep the stroke's order
  // even where the line comes back near itself (hooks).
  line.start_arc_m = project(line, elements.front().start(), 0.0);
  double from = line.start_arc_m;
  for (const StrokeElement& e : elements) {
    from = project(line, e.end(), from);
    line.element_end_arc_m.push_back(from);
  }
  return line;
}

}  // namespace calligraphy
