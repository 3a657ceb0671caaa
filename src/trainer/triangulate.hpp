#pragma once
// Triangles filling a simple polygon, for drawing the filled stroke outlines (ImGui fills only convex
// shapes). Ear clipping (G. H. Meisters, "Polygons have ears", Amer. Math. Monthly 82, 1975): O(n^2)
// per polygon, done once per character.
#include <array>
#include <vector>

#include "calligraphy/model/stroke_outline.hpp"

namespace calligraphy::trainer {

/// Index triples into `polygon`, counter-clockwise in its own coordinates. A polygon that is not simple
/// (self-intersecting) still gets triangles covering it approximately: when no ear is found, the rest is
/// fanned. Fewer than 3 vertices: none.
std::vector<std::array<int, 3>> triangulate(const OutlinePolygon& polygon);

}  // namespace calligraphy::trainer
