#pragma once
// Argument checks shared by the metrics: each names the function, the argument and the index at fault.
// Internal.
#include <span>
#include <string>

#include "calligraphy/analysis/metrics.hpp"

namespace calligraphy::trial_detail {

/// Throws InvalidArgument when `points` is empty or holds a non-finite point (naming its index).
void require_finite_points(std::span<const Vec2> points, const char* function, const char* argument);

/// Throws InvalidArgument when a.size() x b.size() exceeds kMaxCurveCells.
void require_bounded_cells(std::size_t rows, std::size_t columns, const char* function);

/// Throw InvalidArgument naming the option out of range.
void require_valid_options(const KinematicsOptions& options);
void require_valid_options(const CurveComparisonOptions& options);
void require_valid_options(const MetricsOptions& options);

}  // namespace calligraphy::trial_detail
