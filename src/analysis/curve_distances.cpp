#include "analysis/curve_distances.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "analysis/input_checks.hpp"

namespace calligraphy {
namespace trial_detail {

// Frechet: Eiter & Mannila (1994), c(i, j) = max(d(a_i, b_j), min(c(i-1, j), c(i-1, j-1), c(i, j-1))), the
// first row and column taking only their one predecessor. DTW: Sakoe & Chiba (1978) without window or
// slope constraint, D(i, j) = d(a_i, b_j) + min(D(i-1, j), D(i-1, j-1), D(i, j-1)); on equal cost the
// diagonal, then the path with fewer point pairs, so the result does not depend on the order of the two
// curves, and the mean is D over the pairs of its path. Row i needs only row i - 1, so two rows of
// b.size() are kept instead of the n x m tables, as separate arrays: a row's distances are computed first in
// a loop the compiler vectorises, and only the recurrences run cell after cell.
CurveDistances frechet_and_dtw(std::span<const Vec2> a, std::span<const Vec2> b, const char* function) {
  require_finite_points(a, function, "the first curve");
  require_finite_points(b, function, "the second curve");
  require_bounded_cells(a.size(), b.size(), function);
  const std::size_t m = b.size();
  std::vector<double> bx(m);
  std::vector<double> by(m);
  for (std::size_t j = 0; j < m; ++j) {
    bx[j] = b[j].x();
    by[j] = b[j].y();
  }
  std::vector<double> distance(m);
  // Eigen's packet square root: std::sqrt in a loop stays scalar (it may set errno), and the square roots
  // were half of this function's time. Both are IEEE-exact, so the distances are the same.
  using Row = Eigen::Map<Eigen::ArrayXd>;
  using ConstRow = Eigen::Map<const Eigen::ArrayXd>;
  const auto columns = static_cast<Eigen::Index>(m);
  const ConstRow bx_row(bx.data(), columns);
  const ConstRow by_row(by.data(), columns);
  Row distance_row(distance.data(), columns);
  const auto distances_to = [&](const Vec2& p) {
    distance_row = ((p.x() - bx_row).square() + (p.y() - by_row).square()).sqrt();
  };
  // Frechet value, DTW cost and DTW pairs of row i - 1 and row i.
  std::vector<double> frechet(m);
  std::vector<double> cost(m);
  std::vector<std::size_t> pairs(m);
  std::vector<double> next_frechet(m);
  std::vector<double> next_cost(m);
  std::vector<std::size_t> next_pairs(m);
  distances_to(a[0]);
  frechet[0] = cost[0] = distance[0];
  pairs[0] = 1;
  for (std::size_t j = 1; j < m; ++j) {
    frechet[j] = std::max(frechet[j - 1], distance[j]);
    cost[j] = cost[j - 1] + distance[j];
    pairs[j] = j + 1;
  }
  for (std::size_t i = 1; i < a.size(); ++i) {
    distances_to(a[i]);
    double left_frechet = std::max(frechet[0], distance[0]);
    double left_cost = cost[0] + distance[0];
    std::size_t left_pairs = i + 1;
    next_frechet[0] = left_frechet;
    next_cost[0] = left_cost;
    next_pairs[0] = left_pairs;
    for (std::size_t j = 1; j < m; ++j) {
      const double reach = std::min({frechet[j], frechet[j - 1], left_frechet});
      // The cheapest predecessor: diagonal, then up, then left; ties to the fewer pairs. Selected without
      // branches, which the data would mispredict.
      const bool up = cost[j] < cost[j - 1] || (cost[j] == cost[j - 1] && pairs[j] < pairs[j - 1]);
      const double from_up_cost = up ? cost[j] : cost[j - 1];
      const std::size_t from_up_pairs = up ? pairs[j] : pairs[j - 1];
      const bool left = left_cost < from_up_cost || (left_cost == from_up_cost && left_pairs < from_up_pairs);
      const double from_cost = left ? left_cost : from_up_cost;
      const std::size_t from_pairs = left ? left_pairs : from_up_pairs;
      left_frechet = std::max(reach, distance[j]);
      left_cost = from_cost + distance[j];
      left_pairs = from_pairs + 1;
      next_frechet[j] = left_frechet;
      next_cost[j] = left_cost;
      next_pairs[j] = left_pairs;
    }
    std::swap(frechet, next_frechet);
    std::swap(cost, next_cost);
    std::swap(pairs, next_pairs);
  }
  return {frechet[m - 1], cost[m - 1] / static_cast<double>(pairs[m - 1])};
}

}  // namespace trial_detail

double discrete_frechet_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  return trial_detail::frechet_and_dtw(a, b, "discrete_frechet_distance").frechet_m;
}

double dtw_mean_distance(std::span<const Vec2> a, std::span<const Vec2> b) {
  return trial_detail::frechet_and_dtw(a, b, "dtw_mean_distance").dtw_m;
}

}  // namespace calligraphy
