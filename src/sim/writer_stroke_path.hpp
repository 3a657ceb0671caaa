#pragma once
// What the simulated writer sees of a stroke and how it plans to write it (private to the sim module):
// the data's median, which the outline shows a person, split into legs at its corners. Nothing here reads
// the fitted elements, feature points or feature planes (the elements are only the fallback for a stroke
// placed without a median, whose outline is then drawn from them).
#include <vector>

#include "calligraphy/model/scene.hpp"

namespace calligraphy::writer_detail {

using Polyline = std::vector<Vec2>;

/// The stroke a person sees: its median [m] (at least two points), or, for a stroke without one, its
/// outline's centre sampled from the elements.
[[nodiscard]] Polyline seen_stroke(const PlacedStroke& stroke);

/// Interior vertices of `line` where it turns by more than `min_turn_deg` within +-`window_m` of arc (the
/// data rounds a corner over two or three vertices): one index per corner, the vertex turning most.
[[nodiscard]] std::vector<std::size_t> corner_vertices(const Polyline& line, double window_m,
                                                       double min_turn_deg);

/// `line` cut into legs at `corners` (vertex indices, ascending): each corner vertex moved by `cut_m[k]`
/// along its inner bisector (< 0: outside), ending one leg and starting the next.
[[nodiscard]] std::vector<Polyline> legs_through_corners(const Polyline& line,
                                                         const std::vector<std::size_t>& corners,
                                                         const std::vector<double>& cut_m);

/// `line` with its end moved by `delta_m` along the line: < 0 cut back (never past its first point),
/// > 0 carried on along its last direction.
[[nodiscard]] Polyline with_end_moved(const Polyline& line, double delta_m);

}  // namespace calligraphy::writer_detail
