#pragma once
/// \file stroke_matcher.hpp
/// The stroke matcher: whether one pen-down path writes the expected stroke of a character, and if not,
/// why. It reads the path as the renderer reads a live pen (the state machine's start neighbourhood, then
/// `StrokeProgressTracker`), so the renderer, a trial's score, the quiz, the trainer and Python give the
/// same verdict for the same path; a refusal is then named by trying the path on the character's other
/// strokes and reversed. Not for the servo path (it allocates).
#include <cstddef>
#include <span>

#include "calligraphy/collision/stroke_progress.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// The verdict on one pen-down path.
struct StrokeMatch {
  bool accepted = false;
  StrokeRefusal refusal = StrokeRefusal::wrong_place;  ///< none when accepted
  /// For wrong_order and wrong_stroke: the stroke of the character the path writes instead (index);
  /// otherwise the expected stroke.
  std::size_t matched_stroke = 0;
  double covered_fraction = 0.0;  ///< the pen's way along the expected stroke / its length, in [0, 1]
  double mean_deviation_m = 0.0;  ///< mean distance of the path from the expected stroke [m]
};

/// Matches the pen-down path `path_m` (points on the paper in writing order [m], at any spacing: it is
/// read as straight lines between them) against stroke `expected` of `character`, the strokes before it
/// written. The path enters the stroke where it first comes within `start_radius_m` of the stroke's start
/// (WS); accepted when the attempt from there is written (it reaches the end, or the path ends within the
/// tolerances). Refusals: wrong_order (it writes a later stroke), wrong_stroke (an earlier stroke, or it
/// set off from the start and left the stroke), backwards (it writes the stroke reversed, or went against
/// it), too_short, wrong_place. Throws InvalidArgument when `expected` is not a stroke of the character, a
/// point is not finite, or the path is empty.
[[nodiscard]] StrokeMatch match_stroke(const PlacedCharacter& character, std::size_t expected,
                                       std::span<const Vec2> path_m, double start_radius_m,
                                       const StrokeAcceptance& acceptance = {});

}  // namespace calligraphy
