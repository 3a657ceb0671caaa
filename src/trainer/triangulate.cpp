#include "trainer/triangulate.hpp"

#include <algorithm>
#include <numeric>

namespace calligraphy::trainer {
namespace {

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// p inside or on the triangle (a, b, c), counter-clockwise.
bool in_triangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  return cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0;
}

}  // namespace

std::vector<std::array<int, 3>> triangulate(const OutlinePolygon& polygon) {
  std::vector<std::array<int, 3>> triangles;
  const int n = static_cast<int>(polygon.size());
  if (n < 3) return triangles;
  std::vector<int> ring(static_cast<std::size_t>(n));
  std::iota(ring.begin(), ring.end(), 0);
  double area = 0.0;
  for (int i = 0, j = n - 1; i < n; j = i++)
    area += polygon[j].x() * polygon[i].y() - polygon[i].x() * polygon[j].y();
  if (area < 0.0) std::reverse(ring.begin(), ring.end());  // counter-clockwise from here on
  const auto at = [&](std::size_t k) -> const Vec2& { return polygon[static_cast<std::size_t>(ring[k])]; };

  std::size_t i = 0;
  std::size_t misses = 0;
  while (ring.size() > 3) {
    const std::size_t size = ring.size();
    const std::size_t prev = (i + size - 1) % size;
    const std::size_t next = (i + 1) % size;
    bool ear = cross(at(prev), at(i), at(next)) > 0.0;
    for (std::size_t k = 0; ear && k < size; ++k) {
      if (k == prev || k == i || k == next) continue;
      if (at(k) == at(prev) || at(k) == at(i) || at(k) == at(next)) continue;
      if (in_triangle(at(k), at(prev), at(i), at(next))) ear = false;
    }
    if (ear) {
      triangles.push_back({ring[prev], ring[i], ring[next]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
      if (i >= ring.size()) i = 0;
      misses = 0;
    } else if (++misses > size) {  // no ear left (not a simple polygon): fan the rest
      for (std::size_t k = 1; k + 1 < ring.size(); ++k) triangles.push_back({ring[0], ring[k], ring[k + 1]});
      return triangles;
    } else {
      i = next;
    }
  }
  triangles.push_back({ring[0], ring[1], ring[2]});
  return triangles;
}

}  // namespace calligraphy::trainer
