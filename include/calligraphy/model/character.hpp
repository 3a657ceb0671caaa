#pragma once
/// \file character.hpp
/// The character model of paper section 3: a character is a sequence of typical strokes; a typical
/// stroke is a sequence of stroke elements joined at feature points. Coordinates are in the data's
/// units: hanzi-writer-data's 1024 box, x right, y up, upper-left (0, 900), lower-right (1024, -124).
#include <string>
#include <vector>

#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// The data box of hanzi-writer-data (Make Me a Hanzi): x in [0, 1024], y in [-124, 900], y up.
inline constexpr double kDataBoxSize = 1024.0;
inline constexpr double kDataBoxTop = 900.0;
inline constexpr double kDataBoxBottom = -124.0;

/// One stroke of a character. Feature points are the element joints: feature point k is the start of
/// element k, and the last one is the end of the last element, so there are elements.size() + 1.
struct Stroke {
  int typical_id = 0;                   ///< 1-39, see typical_strokes.hpp
  std::vector<StrokeElement> elements;  ///< in writing direction, each starting where the last ended
  std::vector<double>
      attraction_factors;    ///< one per feature point, dimensionless (scales the guidance stiffness)
  std::vector<Vec2> median;  ///< the source polyline (data units), kept for drawing and checks

  [[nodiscard]] std::size_t feature_point_count() const { return elements.size() + 1; }
  /// Feature point k (data units). Precondition: k < feature_point_count().
  [[nodiscard]] const Vec2& feature_point(std::size_t k) const {
    return k < elements.size() ? elements[k].start() : elements.back().end();
  }
};

/// A modelled character.
struct Character {
  char32_t code_point = 0;
  std::string source;           ///< where the data came from (file path or "embedded")
  std::vector<Stroke> strokes;  ///< in standard stroke order
};

/// The character's data as in the paper's Table 3: structural data (control points) and sequence
/// data (typical-stroke IDs, feature-point indices into the control points).
struct CharacterTable {
  std::vector<int> typical_stroke_ids;
  std::vector<Vec2> control_points;  ///< shared joints stored once (data units)
  /// Per stroke, per element: indices of its control points into `control_points`.
  std::vector<std::vector<std::vector<int>>> element_control_indices;
  /// Per stroke: indices of its feature points into `control_points`.
  std::vector<std::vector<int>> feature_point_indices;

  [[nodiscard]] std::size_t feature_point_count() const;
};

/// Builds the Table-3 view of a character. Throws InvalidArgument naming the stroke and element (from 1)
/// when an element's degree is outside 1-4.
CharacterTable character_table(const Character& character);

}  // namespace calligraphy
