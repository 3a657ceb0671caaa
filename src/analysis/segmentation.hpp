#pragma once
// Cutting a pen trace into pen-down segments. Internal.
#include <span>
#include <vector>

#include "calligraphy/analysis/score.hpp"

namespace calligraphy::trial_detail {

/// Every maximal run of pen-down samples, in order, with `ignored` set for runs with fewer than
/// `min_samples` samples, a path shorter than `min_length_m` (or of
/// zero length) or no time span. Other fields left empty.
std::vector<WrittenSegment> pen_down_segments(std::span<const PenSample> trace, std::size_t min_samples,
                                              double min_length_m);

}  // namespace calligraphy::trial_detail
