#include <algorithm>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "analysis/input_checks.hpp"

namespace calligraphy {

// Eiter & Mannila (1994): c(i, j) = max(d(a_i, b_j), min(c(i-1, j), c(i-1, j-1), c(i, j-1))), with the
// first row and column taking only their one predecessor. Row i needs only row i - 1, so two rows of
// b.size() are kept instead of the n x m table.
double discrete_frechet_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  trial_detail::require_finite_points(a, "discrete_frechet_distance", "the first curve");
  trial_detail::require_finite_points(b, "discrete_frechet_distance", "the second curve");
  trial_detail::require_bounded_cells(a.size(), b.size(), "discrete_frechet_distance");
  const std::size_t m = b.size();
  std::vector<double> previous(m);
  std::vector<double> current(m);
  previous[0] = (a[0] - b[0]).norm();
  for (std::size_t j = 1; j < m; ++j) previous[j] = std::max(previous[j - 1], (a[0] - b[j]).norm());
  for (std::size_t i = 1; i < a.size(); ++i) {
    current[0] = std::max(previous[0], (a[i] - b[0]).norm());
    for (std::size_t j = 1; j < m; ++j) {
      const double reach = std::min({previous[j], previous[j - 1], current[j - 1]});
      current[j] = std::max(reach, (a[i] - b[j]).norm());
    }
    std::swap(previous, current);
  }
  return previous[m - 1];
}

}  // namespace calligraphy
