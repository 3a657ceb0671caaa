#pragma once
/// \file typical_strokes.hpp
/// The 39 typical strokes (paper section 3.1, Fig. 7): every character is a sequence of these, each
/// with an ID that never changes. The set is the 6 flat strokes and the 25 turning strokes of
/// GF 2001-2001, plus 8 common variants (REFERENCE.md section 3). Acronyms and code points follow the
/// Unicode CJK Strokes block (U+31C0-U+31E5) where one exists.
#include <optional>
#include <span>
#include <string_view>

namespace calligraphy {

/// One piece of a typical stroke's element template: the nominal direction in which the pen moves
/// at the start and at the end of the piece, in degrees in the data's y-up frame (0 = right, 90 = up,
/// -90 = down). A straight piece has equal start and end directions; a bend differs.
struct StrokePieceTemplate {
  double start_direction_deg;
  double end_direction_deg;
  bool short_piece;  ///< a hook (钩) or tick: short compared with the rest of the stroke
};

/// A typical stroke. `id` is 1-39, constant forever.
struct TypicalStroke {
  int id;
  std::string_view acronym;   ///< e.g. "HZG"
  std::string_view name_zh;   ///< e.g. "横折钩"
  std::string_view pinyin;    ///< e.g. "héng zhé gōu"
  char32_t unicode;           ///< U+31C0..U+31E5, or 0 where the block has no character
  bool compound;              ///< false: a basic stroke of one element (paper section 3.2)
  std::span<const StrokePieceTemplate> pieces;  ///< element template, corner to corner
  double default_attraction;  ///< default attraction factor of its feature points (dimensionless)
};

/// Direction tolerance of the templates: Kai-style horizontals rise 5-15 degrees and verticals lean
/// (REFERENCE.md section 2), so pieces match within this many degrees.
inline constexpr double kTypicalStrokeDirectionToleranceDeg = 35.0;

/// All 39 typical strokes, ordered by ID (index i holds ID i + 1).
std::span<const TypicalStroke> typical_strokes();
/// The typical stroke with this ID. Throws InvalidArgument outside 1-39.
const TypicalStroke& typical_stroke(int id);
/// Looks up an acronym ("HZG"); empty when unknown.
std::optional<int> typical_stroke_id(std::string_view acronym);

}  // namespace calligraphy
