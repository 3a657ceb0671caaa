#include "calligraphy/analysis/stroke_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// Longest straight step fed to the tracker [m]: a recorded path is read as straight lines between its
// points, as fine as a 1 kHz pen at 250 mm/s, so that a sparse path (a median's few vertices, a 60 Hz
// pointer) is read as the renderer would read the same motion.
constexpr double kStep_m = 0.00025;
// Most pieces one step of the path is cut into (a step of 262 m): a longer step, nowhere near a character,
// is read more coarsely rather than overflowing the count (a finite step can have an infinite length).
constexpr int kMaxPieces = 1 << 20;

// Throws InvalidArgument, naming `function`, for an empty path, a point that is not finite, a start radius
// that is not finite and > 0, or an invalid acceptance.
void check_attempt_arguments(const char* function, std::span<const Vec2> path, double start_radius_m,
                             const StrokeAcceptance& acceptance) {
  if (path.empty()) throw InvalidArgument(std::string(function) + ": an empty path");
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (!path[i].allFinite()) {
      throw InvalidArgument(std::string(function) + ": path point " + std::to_string(i) + " is not finite");
    }
  }
  if (!(start_radius_m > 0.0) || !std::isfinite(start_radius_m)) {
    throw InvalidArgument(std::string(function) + ": start radius " + shortest_decimal(start_radius_m) +
                          " m must be > 0");
  }
  acceptance.validate();
}

// Throws InvalidArgument, naming `function` and the stroke, when the stroke has no element or no centre line
// for its elements (it was not placed by Scene::lay_out): the tracker reads both.
void check_stroke(const char* function, const PlacedStroke& stroke, const std::string& name) {
  const StrokeCentreLine& line = stroke.centre_line;
  if (stroke.elements.empty() || line.points_m.size() < 2 || line.arc_m.size() != line.points_m.size() ||
      line.element_end_arc_m.size() != stroke.elements.size()) {
    throw InvalidArgument(std::string(function) + ": " + name +
                          " has no elements or no centre line (place it with Scene::lay_out)");
  }
}

// Feeds the path to a tracker as the renderer would: WS from the first point within the start
// neighbourhood; the path's end is the lift. The arguments are checked.
StrokeAttempt attempt(const PlacedStroke& stroke, std::span<const Vec2> path, double start_radius_m,
                      const StrokeAcceptance& acceptance) {
  StrokeAttempt result;
  StrokeProgressTracker tracker;
  bool written_on_the_way = false;  // completed before the path's end (left the end neighbourhood along it)
  const auto feed = [&](const Vec2& p) {
    if (written_on_the_way) return;
    if (!tracker.in_attempt()) {
      if (result.entered || (p - stroke.start()).norm() > start_radius_m) return;
      result.entered = true;
      tracker.begin(stroke, p, acceptance);
    }
    written_on_the_way = tracker.update(p);
  };
  feed(path.front());
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (written_on_the_way || (result.entered && !tracker.in_attempt())) break;  // feed reads no more
    const Vec2 step = path[i] - path[i - 1];
    const double step_m = step.norm();
    // Before the start neighbourhood is entered, a step that cannot reach it (by the triangle inequality,
    // with a margin for rounding) feeds nothing.
    if (!result.entered && (path[i - 1] - stroke.start()).norm() > start_radius_m + step_m + kStep_m)
      continue;
    const double length_in_steps = std::ceil(step_m / kStep_m);
    const int pieces =
        length_in_steps < kMaxPieces ? std::max(1, static_cast<int>(length_in_steps)) : kMaxPieces;
    for (int k = 1; k <= pieces; ++k) feed(path[i - 1] + step * (static_cast<double>(k) / pieces));
  }
  if (!result.entered) return result;
  result.refusal = tracker.refusal();
  const double way_along_m = tracker.way_along_m();
  const double length_m = tracker.stroke_length_m();
  result.mean_deviation_m = tracker.mean_deviation_m();
  result.written = written_on_the_way || tracker.lift();
  if (result.written) result.refusal = StrokeRefusal::none;
  result.covered_fraction =
      length_m > 0.0 ? std::clamp(way_along_m / length_m, 0.0, 1.0) : (result.written ? 1.0 : 0.0);
  return result;
}

}  // namespace

StrokeMatch match_stroke(const PlacedCharacter& character, std::size_t expected, std::span<const Vec2> path_m,
                         double start_radius_m, const StrokeAcceptance& acceptance) {
  if (expected >= character.strokes.size()) {
    throw InvalidArgument("match_stroke: stroke " + std::to_string(expected) + " of a character with " +
                          std::to_string(character.strokes.size()) + " strokes");
  }
  check_attempt_arguments("match_stroke", path_m, start_radius_m, acceptance);
  for (std::size_t k = 0; k < character.strokes.size(); ++k)
    check_stroke("match_stroke", character.strokes[k], "stroke " + std::to_string(k));
  const PlacedStroke& stroke = character.strokes[expected];
  const StrokeAttempt own = attempt(stroke, path_m, start_radius_m, acceptance);
  StrokeMatch match;
  match.matched_stroke = expected;
  match.entered = own.entered;
  match.covered_fraction = own.covered_fraction;
  match.mean_deviation_m = own.mean_deviation_m;
  if (own.written) {
    match.accepted = true;
    match.refusal = StrokeRefusal::none;
    return match;
  }
  // Another stroke of the character: a later one is out of order, an earlier one written again.
  for (std::size_t k = 0; k < character.strokes.size(); ++k) {
    if (k == expected) continue;
    if (attempt(character.strokes[k], path_m, start_radius_m, acceptance).written) {
      match.refusal = k > expected ? StrokeRefusal::wrong_order : StrokeRefusal::wrong_stroke;
      match.matched_stroke = k;
      return match;
    }
  }
  std::vector<Vec2> reversed(path_m.rbegin(), path_m.rend());
  if (attempt(stroke, reversed, start_radius_m, acceptance).written) {
    match.refusal = StrokeRefusal::backwards;
    return match;
  }
  match.refusal = own.entered ? own.refusal : StrokeRefusal::wrong_place;
  return match;
}

StrokeAttempt attempt_stroke(const PlacedStroke& stroke, std::span<const Vec2> path_m, double start_radius_m,
                             const StrokeAcceptance& acceptance) {
  check_attempt_arguments("attempt_stroke", path_m, start_radius_m, acceptance);
  check_stroke("attempt_stroke", stroke, "the stroke");
  return attempt(stroke, path_m, start_radius_m, acceptance);
}

}  // namespace calligraphy
