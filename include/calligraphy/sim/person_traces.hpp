#pragma once
/// \file person_traces.hpp
/// Labelled pen paths for testing stroke acceptance against what the engine did not make: each is built
/// from the data's median of a stroke (hanzi-writer-data, what the outline shows a person), never from
/// the fitted elements, the feature planes or the centre line the matcher reads. Positives are strokes
/// as people write them (scatter at both ends, corners rounded or overshot, drift, tremor, a pointer's
/// 60 Hz samples and pixels); negatives are strokes a matcher must refuse (reversed, half, moved across,
/// another stroke, the next stroke first, a scribble). Distributions and their sources:
/// docs/stroke-acceptance.md.
#include <cstddef>
#include <random>
#include <vector>

#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// The kinds of labelled paths.
enum class TraceKind {
  // Positives: the stroke, written.
  median,            ///< the data's median vertices as they are
  human,             ///< human pace: offset, turn and scale of the copy, drift, tremor, ends short or past
  corners_cut,       ///< as `human`, corners rounded inside by 2-5 mm of smoothing
  corners_overshot,  ///< as `human`, each corner overshot outside by 1-2.5 mm before turning
  ends_short,        ///< as `human`, lifted 0.5-3 mm short of the end (at most a fifth of the stroke)
  ends_past,         ///< as `human`, carried 0.5-4 mm past the end
  pointer,           ///< a mouse: 60 Hz samples at 60-110 mm/s, wobble, 0.15 mm pixels, lifted short
  // Negatives: a matcher must not credit the expected stroke.
  reversed,       ///< a `human` path from the end to the start
  half,           ///< the first or the second half of the stroke, written as `human` (ends exact)
  shifted,        ///< a `human` path (without its own offset), every point moved 4-8 mm across it
  other_stroke,   ///< a `human` path of another stroke of the character
  swapped_order,  ///< a `human` path of the next stroke, written first
  scribble,       ///< a zig-zag from the stroke's start
  shifted_8mm,    ///< as `shifted`, moved exactly 8 mm across: the acceptance target's own shift
};

/// Every kind, positives first (a kind added later comes last, so that the others draw the same paths).
inline constexpr TraceKind kTraceKinds[] = {
    TraceKind::median,     TraceKind::human,      TraceKind::corners_cut,  TraceKind::corners_overshot,
    TraceKind::ends_short, TraceKind::ends_past,  TraceKind::pointer,      TraceKind::reversed,
    TraceKind::half,       TraceKind::shifted,    TraceKind::other_stroke, TraceKind::swapped_order,
    TraceKind::scribble,   TraceKind::shifted_8mm};

/// True for the kinds that write the stroke.
[[nodiscard]] bool is_positive(TraceKind kind) noexcept;
/// "median", "human", "corners_cut", ... as in the enum.
[[nodiscard]] const char* to_string(TraceKind kind) noexcept;
/// True when `kind` can be made for stroke `stroke` of `character` (other_stroke needs two strokes,
/// swapped_order a next stroke).
[[nodiscard]] bool trace_applies(const PlacedCharacter& character, std::size_t stroke,
                                 TraceKind kind) noexcept;

/// A pen-down path [m] of `kind` for stroke `stroke` of `character`, drawn from `random`. Reads only the
/// strokes' `median_m`. Throws InvalidArgument when the kind does not apply or the stroke has no median.
[[nodiscard]] std::vector<Vec2> person_trace(const PlacedCharacter& character, std::size_t stroke,
                                             TraceKind kind, std::mt19937_64& random);

/// `line_m` [m] (another hand's stroke, such as KanjiVG's centre line) written as a position-only pen
/// writes it at a person's pace, as the `pointer` kind does but following the line as given, with no
/// copy offset, drift or wobble of its own: a minimum-jerk motion at 60-110 mm/s sampled at 60 Hz on
/// 0.15 mm pixels, released 0.2-1.5 mm (at most 12 %) short of its end. Throws InvalidArgument for a
/// line of fewer than 2 distinct points.
[[nodiscard]] std::vector<Vec2> pointer_trace(const std::vector<Vec2>& line_m, std::mt19937_64& random);

}  // namespace calligraphy
