#pragma once
// Frechet and DTW in one pass over the n x m table of point distances, each distance computed once: the
// public `discrete_frechet_distance` and `dtw_mean_distance` and `compare_curves` (which needs both) are
// this one function. Internal.
#include <span>

#include "calligraphy/analysis/metrics.hpp"

namespace calligraphy::trial_detail {

/// Both distances of `a` against `b`; errors name `function` (the public function called). Throws
/// InvalidArgument for an empty curve, a non-finite point or more than kMaxCurveCells cells.
CurveDistances frechet_and_dtw(std::span<const Vec2> a, std::span<const Vec2> b, const char* function);

}  // namespace calligraphy::trial_detail
