#include "analysis/segmentation.hpp"

#include <cmath>
#include <string>

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
                            std::to_string(s.time_s) + " s after " + std::to_string(trace[i - 1].time_s) +
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

}  // namespace trial_detail
}  // namespace calligraphy
