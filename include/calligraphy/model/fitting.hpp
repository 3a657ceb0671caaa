#pragma once
/// \file fitting.hpp
/// Fits a hanzi-writer-data median polyline into stroke elements (paper section 3.3-3.4): feature
/// points at corners, LSEs where straight, Bezier CSEs where bent, and a typical-stroke ID.
/// All lengths are in the data's units (the 1024 box).
#include <span>
#include <string_view>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/character.hpp"

namespace calligraphy {

/// Parameters of `fit_stroke`. Lengths in data units (1024 per character box). The real-valued fields are
/// in their table (`ParameterTable<FitOptions>`: each finite, the lengths and the angle > 0, the hook trim
/// >= 0, the angle at most 180 degrees); `max_degree` is checked beside it.
struct FitOptions {
  /// Max deviation of the fitted elements from the (trimmed) median. Governs the trade between
  /// the number of elements and fidelity.
  double tolerance = 10.0;
  /// A corner is a turn of at least this many degrees within `corner_window` along the median.
  double corner_angle_deg = 70.0;
  /// Arc length (data units) over which turning is summed when looking for corners; wider bends are
  /// fitted as curves. Summed over a window because hanzi-writer-data rounds corners over 2-3 median
  /// vertices; +-48 units worked in an experiment with scratch code outside this project.
  double corner_window = 48.0;
  /// Entry and exit brush hooks: an end segment shorter than this that turns more than 30 degrees is
  /// trimmed (hanzi-writer-data medians keep the brush's entry and exit hooks; 16-32 units worked in
  /// an experiment with scratch code outside this project).
  double hook_trim_length = 32.0;
  /// Highest Bezier degree used (2-4).
  int max_degree = 3;
};

/// The real-valued fields of FitOptions (parameter_table.hpp).
template <>
struct ParameterTable<FitOptions> {
  static constexpr std::string_view name = "FitOptions";
  [[nodiscard]] static std::span<const ParameterField<FitOptions>> fields() noexcept;
};

/// A piece of a stroke between two corners: the unit of classification.
struct StrokePiece {
  double start_direction_deg = 0.0;  ///< direction of motion at the piece's start, y-up degrees
  double end_direction_deg = 0.0;
  double length = 0.0;  ///< data units
  /// Turn of the last fifth of the piece against the fifth to third before it (degrees, counter-
  /// clockwise positive): the curl back toward the vertical that ends a 左点.
  double exit_turn_deg = 0.0;
  std::size_t first_element = 0;  ///< elements [first_element, end_element) form the piece
  std::size_t end_element = 0;
};

/// Result of fitting one median.
struct FittedStroke {
  Stroke stroke;                    ///< elements, attraction factors, typical ID, median
  std::vector<StrokePiece> pieces;  ///< corner-to-corner pieces
  /// Max distance from the (trimmed) median's points to the elements [data units]. Exact for medians of
  /// up to 64 points (all of hanzi-writer-data); for longer ones, when the exact value would cost more
  /// than 64 point-segment distances per point and curve sample (a median overlapping itself many
  /// times), the max distance of each piece's points to the piece's own elements, an upper bound.
  double max_deviation = 0.0;
};

/// Largest |x| or |y| of a median point that `fit_stroke` accepts: squared distances between such
/// points stay finite. (Character files are held to the far smaller kMaxDataCoordinate.)
inline constexpr double kMaxFitCoordinate = 1e150;

/// Fits one median (at least one point; a single point gives a zero-length LSE, paper rule (d)).
/// The work is bounded by the number of points (about linear in it), whatever the coordinates.
/// Throws InvalidArgument for non-finite points, points beyond kMaxFitCoordinate or options out of range.
FittedStroke fit_stroke(std::span<const Vec2> median, const FitOptions& options = {});

/// Typical-stroke classification of fitted pieces by template matching: the least cost over the 39
/// templates of typical_strokes.hpp and a few observed forms of them, the cost being the squared
/// direction errors in units of the templates' tolerances plus soft penalties for piece counts, hook
/// fractions and lengths. A short down-right first piece is ignored as the brush's entry. Validated
/// against cnchar-order (docs/classification.md). Returns an ID 1-39; throws InvalidArgument when
/// `pieces` is empty.
int classify_pieces(std::span<const StrokePiece> pieces);

/// Fits every median of a character, in stroke order.
Character fit_character(char32_t code_point, const std::vector<std::vector<Vec2>>& medians,
                        std::string source, const FitOptions& options = {});

}  // namespace calligraphy
