#include "analysis/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

void validate_pen_trace(std::span<const PenSample> trace) {
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const PenSample& s = trace[i];
    if (!std::isfinite(s.time_s) || !s.position_m.allFinite()) {
      throw InvalidArgument("pen trace: sample " + std::to_string(i) + " has a non-finite time or position");
    }
    if (i > 0 && s.time_s < trace[i - 1].time_s) {
      throw InvalidArgument("pen trace: time goes backwards at sample " + std::to_string(i) + " (" +
                            shortest_decimal(s.time_s) + " s after " + shortest_decimal(trace[i - 1].time_s) +
                            " s)");
    }
  }
}

namespace trial_detail {

std::vector<WrittenSegment> pen_down_segments(std::span<const PenSample> trace, std::size_t min_samples,
                                              double min_length_m) {
  std::vector<WrittenSegment> segments;
  std::size_t i = 0;
  while (i < trace.size()) {
    if (!trace[i].pen_down) {
      ++i;
      continue;
    }
    WrittenSegment segment;
    segment.begin = i;
    double length = 0.0;
    for (++i; i < trace.size() && trace[i].pen_down; ++i)
      length += (trace[i].position_m - trace[i - 1].position_m).norm();
    segment.end = i;
    const bool spans_time = trace[segment.end - 1].time_s > trace[segment.begin].time_s;
    const bool moves = length > 0.0 && length >= min_length_m;
    segment.ignored = segment.end - segment.begin < min_samples || !moves || !spans_time;
    segments.push_back(segment);
  }
  return segments;
}

std::vector<std::size_t> character_of_samples(const Scene& scene, std::span<const PenSample> trace) {
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> owner(trace.size(), kNone);
  std::vector<std::size_t> inside(scene.characters.size());
  std::size_t i = 0;
  while (i < trace.size()) {
    if (!trace[i].pen_down) {
      ++i;
      continue;
    }
    std::size_t end = i;
    std::fill(inside.begin(), inside.end(), 0);
    for (; end < trace.size() && trace[end].pen_down; ++end) {
      for (std::size_t c = 0; c < scene.characters.size(); ++c) {
        if (scene.characters[c].bounding_box.contains(trace[end].position_m)) ++inside[c];
      }
    }
    std::size_t best = 0;
    for (std::size_t c = 1; c < inside.size(); ++c) best = inside[c] > inside[best] ? c : best;
    if (inside[best] == 0) {  // outside every box: the nearest box to where the pen came down
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t c = 0; c < scene.characters.size(); ++c) {
        const double distance = scene.characters[c].bounding_box.exteriorDistance(trace[i].position_m);
        if (distance < nearest) {
          nearest = distance;
          best = c;
        }
      }
    }
    std::fill(owner.begin() + static_cast<std::ptrdiff_t>(i),
              owner.begin() + static_cast<std::ptrdiff_t>(end), best);
    i = end;
  }
  return owner;
}

}  // namespace trial_detail
}  // namespace calligraphy
