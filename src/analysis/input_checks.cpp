#include "analysis/input_checks.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy::trial_detail {

void require_finite_points(std::span<const Vec2> points, const char* function, const char* argument) {
  if (points.empty()) throw InvalidArgument(std::string(function) + ": " + argument + " has no point");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw InvalidArgument(std::string(function) + ": point " + std::to_string(i) + " of " + argument +
                            " is not finite");
    }
  }
}

void require_bounded_cells(std::size_t rows, std::size_t columns, const char* function) {
  // rows > kMaxCurveCells / columns avoids the overflow of rows * columns.
  if (columns != 0 && rows > kMaxCurveCells / columns) {
    throw InvalidArgument(std::string(function) + ": " + std::to_string(rows) + " x " +
                          std::to_string(columns) + " points exceed the bound of " +
                          std::to_string(kMaxCurveCells) +
                          " cells; resample the curves first (compare_curves does)");
  }
}

void require_valid_options(const KinematicsOptions& options) {
  check_parameters(options);
  if (options.max_grid_points < 16) {
    throw InvalidArgument("KinematicsOptions.max_grid_points = " + std::to_string(options.max_grid_points) +
                          " must be >= 16");
  }
}

void require_valid_options(const CurveComparisonOptions& options) {
  check_parameters(options);
  if (options.max_points < 2 || options.max_points > 4096) {
    throw InvalidArgument("CurveComparisonOptions.max_points = " + std::to_string(options.max_points) +
                          " must be in [2, 4096]");
  }
}

void require_valid_options(const MetricsOptions& options) {
  check_parameters(options);
  require_valid_options(options.curves);
  require_valid_options(options.kinematics);
}

}  // namespace calligraphy::trial_detail
