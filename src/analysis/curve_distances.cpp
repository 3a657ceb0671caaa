#include "analysis/curve_distances.hpp"

#include <algorithm>
#include <vector>

#include "analysis/input_checks.hpp"

namespace calligraphy {
namespace trial_detail {
namespace {

// A cell of the tables: the Frechet value c(i, j), and for DTW the least sum of point distances of a path
// from (0, 0) to the cell with the number of point pairs on that path (to turn the sum into a mean).
struct CurveCell {
  double frechet = 0.0;
  double cost = 0.0;
  std::size_t pairs = 0;
};

// The cheapest DTW predecessor; on equal cost the diagonal, then the shorter path, so the result does not
// depend on the order of the two curves.
const CurveCell& cheapest(const CurveCell& diagonal, const CurveCell& up, const CurveCell& left) {
  const CurveCell* best = &diagonal;
  for (const CurveCell* c : {&up, &left}) {
    if (c->cost < best->cost || (c->cost == best->cost && c->pairs < best->pairs)) best = c;
  }
  return *best;
}

}  // namespace

// Frechet: Eiter & Mannila (1994), c(i, j) = max(d(a_i, b_j), min(c(i-1, j), c(i-1, j-1), c(i, j-1))), the
// first row and column taking only their one predecessor. DTW: Sakoe & Chiba (1978) without window or
// slope constraint, D(i, j) = d(a_i, b_j) + min(D(i-1, j), D(i-1, j-1), D(i, j-1)). Row i needs only row
// i - 1, so two rows of b.size() are kept instead of the n x m tables.
CurveDistances frechet_and_dtw(std::span<const Vec2> a, std::span<const Vec2> b, const char* function) {
  require_finite_points(a, function, "the first curve");
  require_finite_points(b, function, "the second curve");
  require_bounded_cells(a.size(), b.size(), function);
  const std::size_t m = b.size();
  std::vector<CurveCell> previous(m);
  std::vector<CurveCell> current(m);
  const double d00 = (a[0] - b[0]).norm();
  previous[0] = {d00, d00, 1};
  for (std::size_t j = 1; j < m; ++j) {
    const double d = (a[0] - b[j]).norm();
    previous[j] = {std::max(previous[j - 1].frechet, d), previous[j - 1].cost + d, j + 1};
  }
  for (std::size_t i = 1; i < a.size(); ++i) {
    const double d0 = (a[i] - b[0]).norm();
    current[0] = {std::max(previous[0].frechet, d0), previous[0].cost + d0, i + 1};
    for (std::size_t j = 1; j < m; ++j) {
      const double d = (a[i] - b[j]).norm();
      const double reach = std::min({previous[j].frechet, previous[j - 1].frechet, current[j - 1].frechet});
      const CurveCell& from = cheapest(previous[j - 1], previous[j], current[j - 1]);
      current[j] = {std::max(reach, d), from.cost + d, from.pairs + 1};
    }
    std::swap(previous, current);
  }
  return {previous[m - 1].frechet, previous[m - 1].cost / static_cast<double>(previous[m - 1].pairs)};
}

}  // namespace trial_detail

double discrete_frechet_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  return trial_detail::frechet_and_dtw(a, b, "discrete_frechet_distance").frechet_m;
}

double dtw_mean_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  return trial_detail::frechet_and_dtw(a, b, "dtw_mean_distance").dtw_m;
}

}  // namespace calligraphy
