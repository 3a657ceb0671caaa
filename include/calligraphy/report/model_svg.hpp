#pragma once
// Draws a character's model like the paper's Fig. 13: the stroke elements (LSEs as lines, CSEs as
// Bezier curves), their control points and control polygons, the feature points in red and the stroke
// numbers at the strokes' starts. Model coordinates are the data's y-up box (x 0..1024, y -124..900),
// flipped for SVG (svg y = 900 - y).
#include <string>

#include "calligraphy/model/character.hpp"

namespace calligraphy {

/// A standalone SVG document (UTF-8). Element tags carry class="element", feature points
/// class="feature-point", other control points class="control-point", control polygons
/// class="control-polygon", stroke numbers class="stroke-number", the medians class="median".
std::string model_svg(const Character& character);

}  // namespace calligraphy
