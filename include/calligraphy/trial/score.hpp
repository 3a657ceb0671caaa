#pragma once
/// \file score.hpp
/// Scoring a pen trace against one placed character: the trace is cut into written strokes at pen
/// lifts, each written stroke is matched to a reference stroke with the tests of Hanzi Writer's quiz
/// (chanind/hanzi-writer, src/strokeMatches.ts), and every matched stroke gets the metrics of
/// metrics.hpp. Definitions and sources: docs/metrics.md.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/metrics.hpp"

namespace calligraphy {

/// One sample of a pen trace, in the paper plane of the character's placement.
struct PenSample {
  double time_s = 0.0;
  Vec2 position_m = Vec2::Zero();  ///< pen tip on the paper plane [m]
  bool pen_down = false;           ///< the tip touches the paper
};

/// Throws InvalidArgument naming the first sample index whose time or position is not finite, or whose
/// time is below the previous sample's (equal times are allowed).
void validate_pen_trace(std::span<const PenSample> trace);

/// A maximal run of pen-down samples, in writing order.
struct WrittenSegment {
  std::size_t begin = 0;  ///< first sample index in the trace
  std::size_t end = 0;    ///< one past the last
  /// Too short to be a stroke (fewer than ScoreOptions::min_segment_samples samples, a path shorter than
  /// min_segment_length_m or of zero length, or no time span): counted, but neither matched nor scored.
  bool ignored = false;
  std::optional<std::size_t> matched_stroke;   ///< reference stroke index, when matched
  bool backwards = false;                      ///< matched with its samples reversed
  std::optional<StrokeKinematics> kinematics;  ///< every segment not ignored
};

/// How a trace is cut and matched.
struct ScoreOptions {
  /// Hanzi Writer's leniency: scales its distance, Frechet and length thresholds (bigger = more lenient).
  /// Finite, > 0.
  double leniency = 1.0;
  std::size_t min_segment_samples = 3;  ///< a segment with fewer samples is ignored
  double min_segment_length_m = 1e-3;   ///< a segment with a shorter pen-down path is ignored [m]
  MetricsOptions metrics{};
};

/// The score of one reference stroke.
struct StrokeScore {
  std::size_t index = 0;  ///< in the character's stroke order, 0-based
  int typical_id = 0;
  bool written = false;                ///< a written segment was matched to it
  std::optional<std::size_t> segment;  ///< index into CharacterScore::segments
  bool backwards = false;              ///< written from its end to its start
  /// Metrics of the matched segment against this stroke (for a backwards stroke, Frechet and DTW are taken
  /// against the stroke traversed from its end, so that they measure shape; the direction is in
  /// `backwards`). Absent when the stroke was not written.
  std::optional<StrokeWritingMetrics> metrics;
};

/// The score of a trace against one character.
struct CharacterScore {
  char32_t code_point = 0;
  std::vector<StrokeScore> strokes;          ///< one per reference stroke, in reference order
  std::vector<WrittenSegment> segments;      ///< every pen-down segment, in writing order
  std::size_t strokes_written = 0;           ///< reference strokes matched
  std::vector<std::size_t> missing_strokes;  ///< reference strokes never written, ascending
  std::size_t unmatched_strokes = 0;         ///< scored segments matched to no reference stroke
  std::size_t ignored_segments = 0;          ///< segments too short to score
  std::size_t backwards_strokes = 0;         ///< matched segments written backwards
  /// Pairs of matched segments whose writing order is the reverse of their reference order (the
  /// inversions of the sequence of matched stroke indices): two swapped strokes give 1.
  std::size_t order_errors = 0;
  bool strokes_in_order = false;    ///< at least one stroke written and order_errors == 0
  bool completed_in_order = false;  ///< every reference stroke written and order_errors == 0
  CharacterWritingMetrics totals;
};

/// Hanzi Writer's rule (chanind/hanzi-writer, src/strokeMatches.ts) when another stroke matches a written
/// stroke more closely than the stroke it is tested against: the writer probably wrote that other one,
/// so the test is repeated with the leniency times 0.6 (closer + own) / (2 own), between 0.3 and 0.6.
/// `closer_distance` < `own_distance`, both >= 0 (any unit); 1 when own_distance is 0.
[[nodiscard]] double closer_stroke_leniency_factor(double closer_distance, double own_distance) noexcept;

/// Scores `trace` against `character`. Segments are matched one to one to reference strokes: among the
/// pairs that pass the Hanzi Writer tests (forwards, else backwards; a pair whose segment another stroke
/// matches forwards more closely must pass them again at the leniency `closer_stroke_leniency_factor`
/// gives), as many pairs as possible, and among those the least sum of mean distances (an optimal
/// assignment, Kuhn 1955 / Munkres 1957). Throws
/// InvalidArgument for a bad trace (see validate_pen_trace, and positions too large to convert to data
/// units), a character without strokes, a stroke without elements, a placement that is not finite with a
/// positive scale, or options out of range.
CharacterScore score_trace(const PlacedCharacter& character, std::span<const PenSample> trace,
                           const ScoreOptions& options = {});

}  // namespace calligraphy
