#pragma once
// An independent, high-precision nearest point, to measure the library's methods against (used by
// `calligraphy bench nearest` and by the tests). It shares no code with src/collision: it samples
// the squared distance densely in long double (64-bit mantissa) on coordinates taken relative to the
// first control point in __float128 (exact for these inputs), keeps every sampled local minimum,
// resamples those brackets ever finer down to a width of 1e-15 in t, and evaluates the final
// candidates' squared distance in __float128. Slow (about 0.1 ms per query); header-only so the
// tests can use it without linking the command-line sources.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "calligraphy/model/element.hpp"

namespace calligraphy::cli {

__extension__ typedef __float128 Quad;  // GCC/Clang extension; __extension__ silences -Wpedantic

/// The reference answer: parameter and distance (element units).
struct ReferenceNearest {
  long double t = 0.0L;
  long double distance = 0.0L;
};

namespace reference_detail {

template <typename Real>
struct Planar {
  Real x;
  Real y;
};

template <typename Real>
Real squared_distance(const std::array<Planar<Real>, kMaxElementDegree + 1>& q, int degree,
                      const Planar<Real>& p, Real t) {
  std::array<Planar<Real>, kMaxElementDegree + 1> r = q;
  for (int level = 1; level <= degree; ++level) {
    for (int i = 0; i <= degree - level; ++i) {
      const auto k = static_cast<std::size_t>(i);
      r[k].x = (1 - t) * r[k].x + t * r[k + 1].x;
      r[k].y = (1 - t) * r[k].y + t * r[k + 1].y;
    }
  }
  const Real dx = r[0].x - p.x;
  const Real dy = r[0].y - p.y;
  return dx * dx + dy * dy;
}

struct Bracket {
  long double low;
  long double high;
  long double best_t;
  long double best_value;
};

}  // namespace reference_detail

/// High-precision nearest point of `p` on `element` (finite input).
inline ReferenceNearest reference_nearest_point(const StrokeElement& element, const Vec2& p) {
  using reference_detail::Bracket;
  using reference_detail::Planar;
  using reference_detail::squared_distance;
  const int degree = element.degree;
  std::array<Planar<Quad>, kMaxElementDegree + 1> q_quad{};
  std::array<Planar<long double>, kMaxElementDegree + 1> q_long{};
  const Quad origin_x = element.control[0].x();
  const Quad origin_y = element.control[0].y();
  for (int i = 0; i <= degree; ++i) {
    const auto k = static_cast<std::size_t>(i);
    q_quad[k] = {Quad(element.control[k].x()) - origin_x, Quad(element.control[k].y()) - origin_y};
    q_long[k] = {static_cast<long double>(q_quad[k].x), static_cast<long double>(q_quad[k].y)};
  }
  const Planar<Quad> p_quad{Quad(p.x()) - origin_x, Quad(p.y()) - origin_y};
  const Planar<long double> p_long{static_cast<long double>(p_quad.x), static_cast<long double>(p_quad.y)};
  auto value = [&](long double t) { return squared_distance<long double>(q_long, degree, p_long, t); };

  // Sample [low, high] at `count` + 1 points; every sampled local minimum (with its neighbours)
  // becomes a bracket of the next, finer level.
  constexpr std::size_t kMaxBrackets = 64;
  auto refine = [&](const Bracket& bracket, int count, std::vector<Bracket>& out) {
    std::vector<long double> values(static_cast<std::size_t>(count) + 1);
    const long double step = (bracket.high - bracket.low) / count;
    auto at = [&](int k) { return k == count ? bracket.high : bracket.low + step * k; };
    for (int k = 0; k <= count; ++k) values[static_cast<std::size_t>(k)] = value(at(k));
    for (int k = 0; k <= count; ++k) {
      const auto index = static_cast<std::size_t>(k);
      const bool below_left = k == 0 || values[index] < values[index - 1];
      const bool not_above_right = k == count || values[index] <= values[index + 1];
      if (below_left && not_above_right) {
        out.push_back({at(std::max(k - 1, 0)), at(std::min(k + 1, count)), at(k), values[index]});
      }
    }
  };
  std::vector<Bracket> brackets{{0.0L, 1.0L, 0.0L, value(0.0L)}};
  std::vector<Bracket> next;
  bool first_level = true;
  while (brackets.front().high - brackets.front().low > 1e-15L) {
    next.clear();
    for (const Bracket& bracket : brackets) refine(bracket, first_level ? 1024 : 32, next);
    first_level = false;
    if (next.empty()) break;
    // Keep the most promising brackets; many appear only where the distance is flat to rounding.
    std::sort(next.begin(), next.end(),
              [](const Bracket& a, const Bracket& b) { return a.best_value < b.best_value; });
    if (next.size() > kMaxBrackets) next.resize(kMaxBrackets);
    brackets.swap(next);
  }
  // The endpoints are always candidates; the final choice is made in __float128.
  ReferenceNearest best;
  Quad best_value = squared_distance<Quad>(q_quad, degree, p_quad, Quad(0));
  auto offer = [&](long double t) {
    const Quad candidate = squared_distance<Quad>(q_quad, degree, p_quad, Quad(t));
    if (candidate < best_value) {
      best_value = candidate;
      best.t = t;
    }
  };
  for (const Bracket& bracket : brackets) offer(bracket.best_t);
  offer(1.0L);
  best.distance = std::sqrt(static_cast<long double>(best_value));
  return best;
}

}  // namespace calligraphy::cli
