#pragma once
/// \file stroke_outline.hpp
/// The filled outline of each stroke, for drawing a character as Hanzi Writer does: hanzi-writer-data's
/// `strokes` (from Make Me a Hanzi) are SVG path data, one path per stroke in stroke order, in the same
/// 1024 data box as the medians (y up). Here they become closed polygons, curves flattened within a
/// tolerance. The outlines are for display only: the haptic model is fitted to the medians.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// One closed polygon in data units (the last vertex joins the first; it is not repeated).
using OutlinePolygon = std::vector<Vec2>;

/// Most vertices all the polygons of one character may have after flattening (the outlines of a
/// hanzi-writer-data character have a few hundred); bounds the work a hostile path can cause.
inline constexpr std::size_t kMaxOutlineVertices = 200'000;
/// Most segments one curve is flattened into.
inline constexpr int kMaxCurveSegments = 256;

/// Parses SVG path data (SVG 1.1, section 8.3 "path data") of the commands M, L, Q, C, S and Z, absolute or
/// relative (m, l, q, c, s, z), with implicit repetition of a command's coordinates, into closed
/// polygons (one per subpath). Quadratic and cubic Bezier curves are flattened into uniform segments,
/// as many as keep the chord within `tolerance` of the curve: the error of a linear interpolant over a
/// step h is at most h^2 max|B''| / 8. Throws DataError naming the byte position for another command,
/// a missing or malformed number, a coordinate beyond +-1e5, a subpath of fewer than 3 vertices, or
/// more than kMaxOutlineVertices vertices; InvalidArgument when tolerance is not > 0.
std::vector<OutlinePolygon> parse_svg_path(std::string_view path, double tolerance = 1.0);

/// The same path data read as open polylines, one per subpath (a pen's line, such as KanjiVG's stroke
/// centre lines, rather than an outline): Z joins the subpath's start. Throws as parse_svg_path, but for
/// a subpath of fewer than 2 distinct vertices.
std::vector<std::vector<Vec2>> parse_svg_polylines(std::string_view path, double tolerance = 1.0);

/// The outlines of a character's strokes, in stroke order (as the medians), data units.
struct CharacterOutlines {
  char32_t code_point = 0;
  std::string source;                                ///< file path, or "embedded:<char>.json"
  std::vector<std::vector<OutlinePolygon>> strokes;  ///< per stroke, its polygons (usually one)
};

/// Even-odd point-in-polygon test (W. R. Franklin's crossing test), data units.
[[nodiscard]] bool polygon_contains(const OutlinePolygon& polygon, const Vec2& point);

}  // namespace calligraphy
