#pragma once
/// \file stroke_matcher.hpp
/// The stroke matcher: whether one pen-down path writes the expected stroke of a character, and if not,
/// why. It reads the path as the renderer reads a live pen (the state machine's start neighbourhood, then
/// `StrokeProgressTracker`), so the renderer, a trial's score, the quiz, the trainer and Python give the
/// same verdict for the same path; a refusal is then named by trying the path on the character's other
/// strokes and reversed. Not for the servo path (it allocates).
#include <cstddef>
#include <span>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"

namespace calligraphy {

/// The verdict on one pen-down path.
struct StrokeMatch {
  bool accepted = false;
  StrokeRefusal refusal = StrokeRefusal::wrong_place;  ///< none when accepted
  /// For wrong_order and wrong_stroke: the stroke of the character the path writes instead (index);
  /// otherwise the expected stroke.
  std::size_t matched_stroke = 0;
  /// The path came within the start radius of the expected stroke's start (WS); when not, the two figures
  /// below are 0 and measure nothing (the report gives no distance then).
  bool entered = false;
  double covered_fraction = 0.0;  ///< the pen's way along the expected stroke / its length, in [0, 1]
  double mean_deviation_m = 0.0;  ///< mean distance of the path from the expected stroke [m]
};

/// One pen-down path tried on one stroke, as the renderer would read it: the pairwise test the stroke
/// matcher is made of (`match_stroke` uses it for the expected stroke, the other strokes and the reversed
/// path; `score_trace` for every pair of a written segment and a reference stroke).
struct StrokeAttempt {
  bool entered = false;  ///< the path came within the start radius of the stroke's start (WS)
  bool written = false;  ///< entered, and the attempt from there writes the stroke
  /// none when written; wrong_place when never entered; otherwise why the lift refused it (too_short,
  /// backwards, wrong_place, wrong_stroke).
  StrokeRefusal refusal = StrokeRefusal::wrong_place;
  double covered_fraction =
      0.0;  ///< the pen's way along the stroke / its length, in [0, 1]; 0 if not entered
  double mean_deviation_m =
      0.0;  ///< mean distance of the path in WS from the centre line [m]; 0 if not entered
};

/// Tries the pen-down path `path_m` (N >= 1 points on the paper in writing order [m], read as straight
/// lines between them in steps of at most 0.25 mm) on `stroke` alone: the attempt begins where the path
/// first comes within `start_radius_m` [m] of the stroke's start, each point is one tick of
/// `StrokeProgressTracker`, and the path's end is the lift. Names no other stroke: a path that writes
/// another stroke is simply not written here. Throws InvalidArgument when the path is empty, a point is not
/// finite, `start_radius_m` is not finite and > 0, `acceptance` is invalid, or the stroke has no elements
/// or no centre line (it was not placed by Scene::lay_out).
[[nodiscard]] StrokeAttempt attempt_stroke(const PlacedStroke& stroke, std::span<const Vec2> path_m,
                                           double start_radius_m, const StrokeAcceptance& acceptance = {});

/// Matches the pen-down path `path_m` (points on the paper in writing order [m], at any spacing: it is
/// read as straight lines between them) against stroke `expected` of `character`, the strokes before it
/// written. The path enters the stroke where it first comes within `start_radius_m` of the stroke's start
/// (WS); accepted when `attempt_stroke` on the expected stroke is written (it reaches the end, or the path
/// ends within the tolerances). A refusal is named by `attempt_stroke` on the other strokes and on the
/// reversed path: wrong_order (it writes a later stroke), wrong_stroke (an earlier stroke, or it set off
/// from the start and left the stroke), backwards (it writes the stroke reversed, or went against it),
/// too_short, wrong_place. Throws InvalidArgument when `expected` is not a stroke of the character, and as
/// `attempt_stroke` (for any stroke of the character).
[[nodiscard]] StrokeMatch match_stroke(const PlacedCharacter& character, std::size_t expected,
                                       std::span<const Vec2> path_m, double start_radius_m,
                                       const StrokeAcceptance& acceptance = {});

}  // namespace calligraphy
