#pragma once
// One-to-one assignment of rows to columns. Internal.
#include <cstddef>
#include <optional>
#include <vector>

namespace calligraphy::trial_detail {

/// `costs[r][c]` is the cost of pairing row r with column c, or nullopt when they cannot be paired. Returns,
/// for each row, its column or nullopt: an assignment with as many pairs as possible and, among those, the
/// least total cost (Hungarian method: Kuhn 1955, Naval Research Logistics Quarterly 2:83-97; Munkres 1957,
/// J. SIAM 5(1):32-38; here with shortest augmenting paths and potentials, O(n^2 m) for n <= m). Costs must
/// be finite and >= 0; every row has the same number of columns.
std::vector<std::optional<std::size_t>> optimal_assignment(
    const std::vector<std::vector<std::optional<double>>>& costs);

}  // namespace calligraphy::trial_detail
