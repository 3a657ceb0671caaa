#include "calligraphy/render/timing_target.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// Parameter steps per element for the arc-length table: a stroke element bends at most a right angle or
// so, and 32 chords follow it to well under a micrometre for the few-centimetre elements of a scene.
constexpr std::size_t kSamplesPerElement = 32;

double minimum_jerk(double u) noexcept {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

}  // namespace

TimingTarget::TimingTarget(const Scene& scene, double mean_speed_m_s) {
  if (!(mean_speed_m_s > 0.0) || !std::isfinite(mean_speed_m_s)) {
    throw InvalidArgument("TimingTarget: mean_speed_m_s = " + shortest_decimal(mean_speed_m_s) +
                          " must be finite and > 0");
  }
  for (const PlacedCharacter& character : scene.characters) {
    for (const PlacedStroke& stroke : character.strokes) {
      StrokeTable table;
      table.elements = stroke.elements.size();
      table.arc_m.reserve(table.elements * (kSamplesPerElement + 1));
      double length = 0.0;
      for (const StrokeElement& element : stroke.elements) {
        Vec2 previous = element.start();
        table.arc_m.push_back(length);
        for (std::size_t i = 1; i <= kSamplesPerElement; ++i) {
          const Vec2 p = element.point(static_cast<double>(i) / kSamplesPerElement);
          length += (p - previous).norm();
          previous = p;
          table.arc_m.push_back(length);
        }
      }
      table.duration_s = length / mean_speed_m_s;
      strokes_.push_back(std::move(table));
    }
  }
}

double TimingTarget::duration_s(std::size_t scene_stroke) const noexcept {
  return scene_stroke < strokes_.size() ? strokes_[scene_stroke].duration_s : 0.0;
}

TimingTarget::Place TimingTarget::place(std::size_t scene_stroke, double elapsed_s) const noexcept {
  if (scene_stroke >= strokes_.size()) return {};
  const StrokeTable& table = strokes_[scene_stroke];
  if (table.elements == 0 || table.arc_m.empty()) return {};
  const double total = table.arc_m.back();
  const double u = table.duration_s > 0.0 ? elapsed_s / table.duration_s : 1.0;
  const double s = total * minimum_jerk(u);
  // The first tabulated arc length at or beyond s; its element and the parameter between its neighbours.
  const auto upper = std::lower_bound(table.arc_m.begin(), table.arc_m.end(), s);
  if (upper == table.arc_m.end()) return {table.elements - 1, 1.0};
  const auto i = static_cast<std::size_t>(upper - table.arc_m.begin());
  const std::size_t per = kSamplesPerElement + 1;
  const std::size_t element = i / per;
  const std::size_t step = i % per;
  if (step == 0) return {element, 0.0};
  const double a = table.arc_m[i - 1];
  const double b = table.arc_m[i];
  const double f = b > a ? (s - a) / (b - a) : 1.0;
  return {element, (static_cast<double>(step - 1) + f) / kSamplesPerElement};
}

Vec2 TimingTarget::attraction_point(std::size_t scene_stroke, double elapsed_s, std::size_t element_index,
                                    const StrokeElement& element) const noexcept {
  const Place target = place(scene_stroke, elapsed_s);
  if (target.element > element_index) return element.end();
  if (target.element < element_index) return element.start();
  return element.point(target.parameter);
}

}  // namespace calligraphy
