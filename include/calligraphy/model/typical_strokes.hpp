#pragma once
/// \file typical_strokes.hpp
/// The 39 typical strokes (paper section 3.1, Fig. 7): every character is a sequence of these, each
/// with an ID that never changes. The set is the 6 flat strokes and the 25 turning strokes of
/// GF 2001-2001, plus 8 common variants (竖撇, 左点, 长点, 卧钩, 平撇, 提捺, 撇钩, 竖弯左).
/// Acronyms and code points follow the Unicode CJK Strokes block (U+31C0-U+31E5) where one exists.
/// `docs/typical-strokes.md` is generated from this table (`calligraphy strokes --markdown`).
#include <limits>
#include <optional>
#include <span>
#include <string_view>

#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// One piece of a typical stroke's element template, from one corner (feature point) to the next.
/// Directions are the pen's direction of motion in degrees in the data's y-up frame (0 = right,
/// 90 = up, -90 = down), measured on the piece's interior (10-40 % and 60-95 % of its length) so
/// that brush entries and exits do not count. The nominal values are those of Kai-style medians:
/// horizontals rise about 10 degrees, verticals lean (as in hanzi-writer-data's medians).
struct StrokePieceTemplate {
  ElementKind kind;            ///< line where straight (start = end direction), bezier where bent
  double start_direction_deg;  ///< nominal direction at the piece's start
  double end_direction_deg;    ///< nominal direction at the piece's end
  double start_tolerance_deg;  ///< one standard deviation of the start direction
  double end_tolerance_deg;    ///< one standard deviation of the end direction
  bool hook;                   ///< a hook (钩) or tick (提): short compared with the rest of the stroke
  double min_length = 0.0;     ///< expected piece length range, data units (1024 box); soft bounds
  double max_length = std::numeric_limits<double>::infinity();
};

/// A piece template from nominal directions [deg] and their tolerances [deg]: a line (LSE) when the
/// start and end directions differ by less than 15 degrees, else a Bezier curve (CSE), after the paper's
/// line segment and curve segment strokes (section 3.2). Lengths in data units (1024 box).
constexpr StrokePieceTemplate piece_template(double start_deg, double end_deg, double start_tolerance_deg,
                                             double end_tolerance_deg, bool hook = false,
                                             double min_length = 0.0,
                                             double max_length = std::numeric_limits<double>::infinity()) {
  constexpr double kBentDeg = 15.0;
  const bool straight = end_deg - start_deg < kBentDeg && start_deg - end_deg < kBentDeg;
  return {straight ? ElementKind::line : ElementKind::bezier,
          start_deg,
          end_deg,
          start_tolerance_deg,
          end_tolerance_deg,
          hook,
          min_length,
          max_length};
}

/// A typical stroke. `id` is 1-39, constant forever.
struct TypicalStroke {
  int id;
  std::string_view acronym;  ///< e.g. "HZG"
  std::string_view name_zh;  ///< e.g. "横折钩"
  std::string_view pinyin;   ///< e.g. "héng zhé gōu"
  char32_t unicode;          ///< U+31C0..U+31E5, or 0 where the block has no character
  bool compound;             ///< false: a basic stroke, one piece (paper section 3.2); true: turns
  std::span<const StrokePieceTemplate> pieces;  ///< element template, corner to corner
  double default_attraction;  ///< attraction factor of its feature points (dimensionless, paper eq. 8)
  double corner_attraction;   ///< attraction factor at its corners (turning feature points)
};

/// All 39 typical strokes, ordered by ID (index i holds ID i + 1).
std::span<const TypicalStroke> typical_strokes();
/// The typical stroke with this ID. Throws InvalidArgument outside 1-39.
const TypicalStroke& typical_stroke(int id);
/// Looks up an acronym ("HZG"); empty when unknown.
std::optional<int> typical_stroke_id(std::string_view acronym);
/// Looks up what a person calls a typical stroke, as `calligraphy strokes` lists it: its acronym in any case
/// ("HZG", "hzg"), its Chinese name ("横折钩") or its CJK stroke character ("㇆"); empty when none. The one
/// reading of `calligraphy characters --typical` and Python's `typical_stroke(key)` (an ID is a number
/// there).
std::optional<int> typical_stroke_id_by_name(std::string_view name);

}  // namespace calligraphy
