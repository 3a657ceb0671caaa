#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "analysis/input_checks.hpp"

namespace calligraphy {
namespace {

// A cell of the DTW table: the least sum of point distances of a path from (0, 0) to the cell, and the
// number of point pairs on that path (to turn the sum into a mean at the end).
struct Cell {
  double cost = 0.0;
  std::size_t pairs = 0;
};

// The cheapest predecessor; on equal cost the diagonal, then the shorter path, so the result does not
// depend on the order of the two curves.
const Cell& cheapest(const Cell& diagonal, const Cell& up, const Cell& left) {
  const Cell* best = &diagonal;
  for (const Cell* c : {&up, &left}) {
    if (c->cost < best->cost || (c->cost == best->cost && c->pairs < best->pairs)) best = c;
  }
  return *best;
}

}  // namespace

// Sakoe & Chiba (1978) without window or slope constraint: D(i, j) = d(a_i, b_j) + min(D(i-1, j),
// D(i-1, j-1), D(i, j-1)). Two rolling rows, as in discrete_frechet_distance.
double dtw_mean_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  trial_detail::require_finite_points(a, "dtw_mean_distance", "the first curve");
  trial_detail::require_finite_points(b, "dtw_mean_distance", "the second curve");
  trial_detail::require_bounded_cells(a.size(), b.size(), "dtw_mean_distance");
  const std::size_t m = b.size();
  std::vector<Cell> previous(m);
  std::vector<Cell> current(m);
  previous[0] = {(a[0] - b[0]).norm(), 1};
  for (std::size_t j = 1; j < m; ++j) previous[j] = {previous[j - 1].cost + (a[0] - b[j]).norm(), j + 1};
  for (std::size_t i = 1; i < a.size(); ++i) {
    current[0] = {previous[0].cost + (a[i] - b[0]).norm(), i + 1};
    for (std::size_t j = 1; j < m; ++j) {
      const Cell& from = cheapest(previous[j - 1], previous[j], current[j - 1]);
      current[j] = {from.cost + (a[i] - b[j]).norm(), from.pairs + 1};
    }
    std::swap(previous, current);
  }
  return previous[m - 1].cost / static_cast<double>(previous[m - 1].pairs);
}

}  // namespace calligraphy
