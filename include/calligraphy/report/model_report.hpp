#pragma once
/// \file model_report.hpp
/// A character's model as the paper reports it (Wang, Zhang & Yao 2006, section 3.5 and Table 3: the
/// number of typical strokes, their IDs, the numbers of control and feature points) and, per stroke, its
/// typical stroke, elements, feature points and attraction factors: what `calligraphy model` prints.
/// Coordinates are the data's 1024-unit box, y up.
#include <string>

#include "calligraphy/model/character.hpp"

namespace calligraphy {

/// The model for people: the Table-3 summary, then one block per stroke with its elements.
std::string model_text(const Character& character);

/// The model as a JSON object (2-space indent, newline-terminated): `character`, `typical_strokes`,
/// `typical_stroke_ids`, `control_points`, `feature_points` and `strokes`, one object per stroke with
/// `typical_id`, `acronym`, `name`, `pinyin`, `unicode` (U+XXXX of the stroke's own code point, or
/// null), `element_count`, `elements` (`kind` line|bezier, `degree`, `control_points` [[x, y], ...]),
/// `feature_points`, `feature_point_indices` and `attraction_factors`.
std::string model_json(const Character& character);

}  // namespace calligraphy
