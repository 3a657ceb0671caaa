// The demonstration's timing (demonstration.hpp).
#include "trainer/demonstration.hpp"

#include <algorithm>
#include <utility>

namespace calligraphy::trainer {

double minimum_jerk(double tau) noexcept {
  const double t = std::clamp(tau, 0.0, 1.0);
  return t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
}

DemoSchedule::DemoSchedule(std::vector<double> stroke_lengths_m, DemoPace pace) : pace_(pace) {
  for (const double length_m : stroke_lengths_m)
    durations_s_.push_back(std::max(kMinStrokeS, std::max(0.0, length_m) / pace_.speed_m_s));
}

double DemoSchedule::duration_s() const noexcept {
  double total = 0.0;
  for (const double d : durations_s_) total += pace_.pause_s + d;
  return total;
}

DemoFrame DemoSchedule::at(double t_s) const noexcept {
  double t = std::max(0.0, t_s);
  for (std::size_t k = 0; k < durations_s_.size(); ++k) {
    if (t < pace_.pause_s) return {k, 0.0, false};
    t -= pace_.pause_s;
    if (t < durations_s_[k]) return {k, minimum_jerk(t / durations_s_[k]), false};
    t -= durations_s_[k];
  }
  return {durations_s_.size(), 1.0, true};
}

double polyline_length(const std::vector<Vec2>& points) noexcept {
  double length = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

std::vector<Vec2> polyline_head(const std::vector<Vec2>& points, double fraction) {
  std::vector<Vec2> head;
  if (points.empty()) return head;
  head.push_back(points.front());
  double left = std::clamp(fraction, 0.0, 1.0) * polyline_length(points);
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double step = (points[i] - points[i - 1]).norm();
    if (step >= left) {
      if (step > 0.0 && left > 0.0)
        head.push_back(points[i - 1] + (points[i] - points[i - 1]) * (left / step));
      return head;
    }
    left -= step;
    head.push_back(points[i]);
  }
  return head;
}

}  // namespace calligraphy::trainer
