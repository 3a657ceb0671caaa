#pragma once
// Corner search of the fitter (paper section 3.3: feature points at corners). Internal; its own file so
// that tests can check the work it does against the number of points.
#include <cstddef>
#include <vector>

#include "calligraphy/model/fitting.hpp"

namespace calligraphy::detail {

/// Work done by one corner search.
struct CornerSearchWork {
  std::size_t centres = 0;  ///< window positions visited (at most kMaxCornerCentresPerPoint per point)
  std::size_t summed = 0;   ///< vertex turns added into a window sum
};

/// Bound on `CornerSearchWork::centres` per median point: a vertex lies in the windows of at most
/// 2 * 12 + 1 centres one step apart (and twice that where rounding halves a step); each jump over an
/// empty stretch costs at most 3 more.
inline constexpr std::size_t kMaxCornerCentresPerPoint = 64;

/// Indices of corner vertices of a median without repeated points, after replacing rounded corners (a
/// run of vertices turning the same way) by the intersection of the lines that enter and leave them.
/// The work is bounded by the number of points, whatever the coordinates' magnitude.
std::vector<std::size_t> find_corners(std::vector<Vec2>& pts, const FitOptions& options,
                                      CornerSearchWork* work = nullptr);

}  // namespace calligraphy::detail
