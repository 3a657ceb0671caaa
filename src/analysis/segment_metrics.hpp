#pragma once
// The metrics of one written segment against its stroke when its kinematics are known already: `score_trace`
// computes them for every segment before matching, so the matched one's record reuses them. Internal.
#include <span>

#include "calligraphy/analysis/metrics.hpp"

namespace calligraphy::trial_detail {

/// `stroke_writing_metrics` with `kinematics` of the same samples and options already computed.
StrokeWritingMetrics stroke_writing_metrics(const StrokeKinematics& kinematics,
                                            std::span<const Vec2> positions_m,
                                            std::span<const StrokeElement> reference_m,
                                            const MetricsOptions& options, bool reference_reversed);

}  // namespace calligraphy::trial_detail
