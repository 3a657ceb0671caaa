#include "analysis/assignment.hpp"

#include <limits>

namespace calligraphy::trial_detail {
namespace {

// Hungarian method on a complete n x m matrix with n <= m (1-based potentials u, v; p[j] is the row given
// column j, 0 for none). Returns the column of each row.
std::vector<std::size_t> hungarian(const std::vector<std::vector<double>>& a, std::size_t n, std::size_t m) {
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0);
  std::vector<double> v(m + 1, 0.0);
  std::vector<std::size_t> p(m + 1, 0);
  std::vector<std::size_t> way(m + 1, 0);
  for (std::size_t i = 1; i <= n; ++i) {
    p[0] = i;
    std::size_t j0 = 0;
    std::vector<double> min_reduced(m + 1, infinity);
    std::vector<bool> used(m + 1, false);
    do {  // grow a shortest-path tree from row i until it reaches a free column
      used[j0] = true;
      const std::size_t i0 = p[j0];
      double delta = infinity;
      std::size_t j1 = 0;
      for (std::size_t j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = a[i0 - 1][j - 1] - u[i0] - v[j];
        if (reduced < min_reduced[j]) {
          min_reduced[j] = reduced;
          way[j] = j0;
        }
        if (min_reduced[j] < delta) {
          delta = min_reduced[j];
          j1 = j;
        }
      }
      for (std::size_t j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          min_reduced[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {  // augment along the path
      const std::size_t j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<std::size_t> column_of_row(n, 0);
  for (std::size_t j = 1; j <= m; ++j) {
    if (p[j] != 0) column_of_row[p[j] - 1] = j - 1;
  }
  return column_of_row;
}

}  // namespace

std::vector<std::optional<std::size_t>> optimal_assignment(
    const std::vector<std::vector<std::optional<double>>>& costs) {
  const std::size_t rows = costs.size();
  const std::size_t columns = rows == 0 ? 0 : costs.front().size();
  std::vector<std::optional<std::size_t>> result(rows);
  if (rows == 0 || columns == 0) return result;
  // A forbidden pair costs more than all allowed pairs together, so the optimum uses as few of them as
  // possible (as many real pairs as possible) and, among those, the least real cost.
  double forbidden = 1.0;
  for (const auto& row : costs) {
    for (const auto& c : row) forbidden += c.value_or(0.0);
  }
  const bool transposed = rows > columns;
  const std::size_t n = transposed ? columns : rows;
  const std::size_t m = transposed ? rows : columns;
  std::vector<std::vector<double>> a(n, std::vector<double>(m));
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns; ++c) {
      const double cost = costs[r][c].value_or(forbidden);
      if (transposed) {
        a[c][r] = cost;
      } else {
        a[r][c] = cost;
      }
    }
  }
  const std::vector<std::size_t> match = hungarian(a, n, m);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t r = transposed ? match[i] : i;
    const std::size_t c = transposed ? i : match[i];
    if (costs[r][c].has_value()) result[r] = c;
  }
  return result;
}

}  // namespace calligraphy::trial_detail
