// Corners found by summed turning over a window sliding along the arc (the Make Me a Hanzi medians
// round corners over 2-3 vertices, so one vertex's angle does not find them).
#include "model/corner_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "calligraphy/model/polyline.hpp"

namespace calligraphy::detail {
namespace {

constexpr double kClusterTurnDeg = 10.0;

// The next window centre: one step on, and at least one representable number on where the step is
// below the rounding of the centre (coordinates near 1e17 and beyond), so that the search always moves.
double advance(double centre, double step, double at_least) {
  double next = centre + step;
  if (!(next > centre)) next = std::nextafter(centre, std::numeric_limits<double>::infinity());
  return std::max(next, at_least);
}

}  // namespace

std::vector<std::size_t> find_corners(std::vector<Vec2>& pts, const FitOptions& options,
                                      CornerSearchWork* work) {
  CornerSearchWork done;
  const std::size_t n = pts.size();
  if (n < 3) return {};
  std::vector<double> turn(n, 0.0);
  std::vector<double> arc(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) arc[i] = arc[i - 1] + (pts[i] - pts[i - 1]).norm();
  for (std::size_t i = 1; i + 1 < n; ++i) turn[i] = turn_deg(pts[i] - pts[i - 1], pts[i + 1] - pts[i]);
  if (!std::isfinite(arc[n - 1])) return {};  // fit_stroke bounds coordinates so that this cannot happen

  // Clusters [first, last] of interior vertices forming one corner each. The window slides along the
  // arc every few units, so a corner rounded over several vertices is summed whole wherever its centre
  // lies. Since arc is non-decreasing, the interior vertices within +-window of a centre are a range
  // [lo, hi) that only moves forward; stretches where the window holds no vertex are jumped over, so
  // the number of centres depends on the number of vertices, not on the length of the arc.
  const double window = options.corner_window;
  std::vector<std::pair<std::size_t, std::size_t>> clusters;
  const double step = std::max(1.0, window / 12.0);
  std::size_t lo = 1;
  double centre = 0.0;
  while (centre <= arc[n - 1]) {
    ++done.centres;
    while (lo + 1 < n && arc[lo] - centre < -window) ++lo;
    if (lo + 1 >= n) break;  // every interior vertex is behind the window
    if (arc[lo] - centre > window) {
      // No vertex until the window reaches arc[lo]: go to the grid centre a step before the first
      // one whose window may hold it (a step early against rounding).
      centre = advance(centre, step, (std::floor((arc[lo] - window) / step) - 1.0) * step);
      continue;
    }
    std::size_t hi = lo;
    double windowed = 0.0;
    for (; hi + 1 < n && arc[hi] - centre <= window; ++hi) windowed += turn[hi];
    done.summed += hi - lo;
    centre = advance(centre, step, 0.0);
    if (std::abs(windowed) < options.corner_angle_deg) continue;
    std::size_t first = n;
    std::size_t last = 0;
    for (std::size_t j = lo; j < hi; ++j) {
      if (turn[j] * windowed > 0.0 && std::abs(turn[j]) > kClusterTurnDeg) {
        first = std::min(first, j);
        last = std::max(last, j);
      }
    }
    if (first > last) continue;
    // Adjacent windows extend one corner; two corners joined by a long straight segment (a vertical
    // and its hook) stay apart even when no vertex lies between them.
    if (!clusters.empty() && first <= clusters.back().second + 1 &&
        turn[first] * turn[clusters.back().first] > 0.0 &&
        arc[first] - arc[clusters.back().second] <= window) {
      clusters.back().second = std::max(clusters.back().second, last);
    } else if (clusters.empty() || first > clusters.back().second) {
      clusters.emplace_back(first, last);
    }
  }
  if (work != nullptr) *work = done;

  // Snap each cluster to one vertex, from the last so that earlier indices stay valid.
  std::vector<std::size_t> corners;
  for (auto it = clusters.rbegin(); it != clusters.rend(); ++it) {
    auto [first, last] = *it;
    std::size_t sharpest = first;
    for (std::size_t j = first; j <= last; ++j) {
      if (std::abs(turn[j]) > std::abs(turn[sharpest])) sharpest = j;
    }
    std::size_t corner = sharpest;
    if (first != last) {
      const Vec2 a = pts[first - 1];
      const Vec2 da = pts[first] - a;
      const Vec2 b = pts[last + 1];
      const Vec2 db = pts[last] - b;
      const double denom = da.x() * db.y() - da.y() * db.x();
      if (std::abs(denom) > 1e-9 * da.norm() * db.norm()) {
        const double s = ((b - a).x() * db.y() - (b - a).y() * db.x()) / denom;
        const Vec2 x = a + s * da;
        if (s > 0.0 && (x - pts[sharpest]).norm() <= window) {
          pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(first + 1),
                    pts.begin() + static_cast<std::ptrdiff_t>(last + 1));
          pts[first] = x;
          for (auto& c : corners) c -= last - first;
          corner = first;
        }
      }
    }
    corners.push_back(corner);
  }
  std::reverse(corners.begin(), corners.end());
  return corners;
}

}  // namespace calligraphy::detail
