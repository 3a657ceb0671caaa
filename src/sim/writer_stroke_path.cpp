#include "sim/writer_stroke_path.hpp"

#include <algorithm>
#include <cmath>

#include "calligraphy/model/polyline.hpp"

namespace calligraphy::writer_detail {
namespace {

constexpr int kSamplesPerElement = 16;  // outline centre of a stroke without a median

}  // namespace

Polyline seen_stroke(const PlacedStroke& stroke) {
  Polyline line = without_repeats(stroke.median_m);
  if (stroke.median_m.size() < 2) {
    line = {stroke.start()};
    for (const StrokeElement& e : stroke.elements) {
      const std::vector<Vec2> samples = sample_element(e, kSamplesPerElement);
      line.insert(line.end(), samples.begin() + 1, samples.end());
    }
  }
  if (line.size() < 2) line.push_back(line.front());
  return line;
}

std::vector<std::size_t> corner_vertices(const Polyline& line, double window_m, double min_turn_deg) {
  const std::size_t n = line.size();
  std::vector<double> arc(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) arc[i] = arc[i - 1] + (line[i] - line[i - 1]).norm();
  std::vector<double> turn(n, 0.0);  // degrees
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const Vec2 in = line[i] - line[i - 1];
    const Vec2 out = line[i + 1] - line[i];
    if (in.norm() > 0.0 && out.norm() > 0.0) turn[i] = turn_deg(in, out);
  }
  std::vector<std::size_t> corners;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    double summed = 0.0;
    bool largest = true;
    for (std::size_t j = 1; j + 1 < n; ++j) {
      if (std::abs(arc[j] - arc[i]) > window_m) continue;
      summed += turn[j];
      // The vertex turning most in its window stands for the corner (the first of equals).
      if (std::abs(turn[j]) > std::abs(turn[i]) || (j < i && std::abs(turn[j]) == std::abs(turn[i])))
        largest = false;
    }
    if (largest && std::abs(summed) > min_turn_deg) corners.push_back(i);
  }
  return corners;
}

std::vector<Polyline> legs_through_corners(const Polyline& line, const std::vector<std::size_t>& corners,
                                           const std::vector<double>& cut_m) {
  std::vector<Polyline> legs(1);
  std::size_t next = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (next < corners.size() && corners[next] == i) {
      const Vec2 in = (line[i] - line[i - 1]).normalized();
      const Vec2 out = (line[i + 1] - line[i]).normalized();
      Vec2 inward = out - in;  // towards the inside of the turn
      const double norm = inward.norm();
      const Vec2 joint = norm > 1e-9 ? Vec2(line[i] + cut_m[next] * inward / norm) : line[i];
      legs.back().push_back(joint);
      legs.push_back(Polyline{joint});
      ++next;
    } else {
      legs.back().push_back(line[i]);
    }
  }
  return legs;
}

Polyline with_end_moved(const Polyline& line, double delta_m) {
  Polyline out = line;
  if (line.size() < 2 || delta_m == 0.0) return out;
  if (delta_m > 0.0) {
    const Vec2 d = line.back() - line[line.size() - 2];
    if (d.norm() > 0.0) out.push_back(line.back() + delta_m * d.normalized());
    return out;
  }
  double cut = std::min(-delta_m, polyline_length(line));
  while (out.size() >= 2) {
    const Vec2 last = out.back();
    const Vec2 before = out[out.size() - 2];
    const double span = (last - before).norm();
    if (span > cut) {
      out.back() = last + (cut / span) * (before - last);
      return out;
    }
    cut -= span;
    out.pop_back();
    if (out.size() == 1) break;
  }
  out.push_back(out.back());
  return out;
}

}  // namespace calligraphy::writer_detail
