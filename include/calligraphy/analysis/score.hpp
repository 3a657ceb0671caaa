#pragma once
/// \file score.hpp
/// Scoring a pen trace against one placed character: the trace is cut into written strokes at pen
/// lifts, each written stroke is matched to a reference stroke with the stroke matcher the renderer uses
/// (analysis/stroke_matcher.hpp, docs/stroke-acceptance.md), and every matched stroke gets the metrics of
/// metrics.hpp. Each written stroke also gets the verdict the renderer would have given it in turn.
/// Definitions and sources: docs/metrics.md.
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// A pen touches the paper when its tip is at most this far above the paper plane [m]: 0.5 mm allows for the
/// tracking noise of a desktop haptic device above a virtual paper plane (a choice). Trials, the pen-trace
/// CSV reader and the quiz use it.
inline constexpr double kPenContactThresholdM = 0.5e-3;

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
  /// The verdict the renderer (and the quiz) would give this segment in sequence:
  /// `match_stroke(character, expected, its path, start_radius_m, acceptance)`, where `expected` is 0 for
  /// the first segment judged and goes up by one after each accepted verdict and after each stroke credited
  /// assisted (`assists_due`). Absent for an ignored segment and once every stroke has been accepted or
  /// credited.
  std::optional<StrokeMatch> verdict;
  /// The stroke the verdict judged, `expected` above (0-based); 0 without a verdict.
  std::size_t due_stroke = 0;
  /// This refused verdict was the `acceptance.assist_after_misses`-th miss on the stroke due: that stroke is
  /// then credited assisted, as the renderer demonstrates and credits it (StrokeAcceptance), and the next is
  /// due. A miss is the renderer's (StrokeAcceptance::counts_as_miss): a refused verdict of a segment the pen
  /// was lifted from (not one the trace ends in) that touched the character's box, near the due stroke's
  /// start or not (with `miss_min_path_m` 0, as records before version 8 ran, only one that came within the
  /// start radius of its start: a lift in WS).
  bool assists_due = false;
};

/// The most pen-down segments one scored trace may have (ScoreOptions::max_segments): a character has at
/// most a few dozen strokes, and every segment is tried on every stroke, so a trace with more is refused
/// up front rather than matched for minutes.
inline constexpr std::size_t kMaxScoredSegments = 10000;

/// How a trace is cut and matched.
struct ScoreOptions {
  /// The stroke matcher's tolerances (SI units): give the renderer's (ForceLawParameters::acceptance) to
  /// get its verdicts. Valid (StrokeAcceptance::validate).
  StrokeAcceptance acceptance{};
  /// Radius of the start neighbourhood a segment must enter a stroke in [m]: the scene's
  /// (SceneLayout::start_radius_m). Finite, > 0.
  double start_radius_m = SceneLayout{}.start_radius_m;
  /// A segment with fewer samples is ignored (the fewest a miss has, kMinMissSamples).
  std::size_t min_segment_samples = kMinMissSamples;
  /// A segment with a shorter pen-down path is ignored [m] (the least path of a miss,
  /// StrokeAcceptance::miss_min_path_m).
  double min_segment_length_m = StrokeAcceptance{}.miss_min_path_m;
  MetricsOptions metrics{};
  /// A trace with more pen-down segments (ignored ones included) is refused before any is matched. > 0.
  std::size_t max_segments = kMaxScoredSegments;
  /// When set, called with the segments matched so far and the segments to match, before the first and
  /// after each (for a progress display); it may throw to stop the scoring.
  std::function<void(std::size_t matched, std::size_t total)> progress;
};

/// The score of one reference stroke.
struct StrokeScore {
  std::size_t index = 0;  ///< in the character's stroke order, 0-based
  int typical_id = 0;
  bool written = false;  ///< a written segment was matched to it
  /// Credited assisted in turn: refused `acceptance.assist_after_misses` times while it was due
  /// (WrittenSegment::assists_due), as the renderer credits it; such a stroke may still be `written` later.
  bool assisted = false;
  std::optional<std::size_t> segment;  ///< index into CharacterScore::segments
  bool backwards = false;              ///< written from its end to its start
  /// Metrics of the matched segment against this stroke (for a backwards stroke, Frechet and DTW are taken
  /// against the stroke traversed from its end, so that they measure shape; the direction is in
  /// `backwards`). Absent when the stroke was not written.
  std::optional<StrokeWritingMetrics> metrics;
};

/// Verdicts refused, by reason (StrokeRefusal).
struct RefusalCounts {
  std::size_t too_short = 0;
  std::size_t backwards = 0;
  std::size_t wrong_place = 0;
  std::size_t wrong_stroke = 0;
  std::size_t wrong_order = 0;
  /// The count of `refusal`; 0 for none.
  [[nodiscard]] std::size_t of(StrokeRefusal refusal) const noexcept;
  /// Counts one more `refusal`; none is not counted.
  void add(StrokeRefusal refusal) noexcept;
  [[nodiscard]] std::size_t total() const noexcept;
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
  /// Segment verdicts accepted (WrittenSegment::verdict): the strokes the renderer would have completed in
  /// turn, writing the trace with the pen.
  std::size_t strokes_accepted = 0;
  /// Strokes credited assisted in turn (StrokeScore::assisted): the renderer's assisted credit, never
  /// counted as accepted. 0 when `acceptance.assist_after_misses` is 0.
  std::size_t strokes_assisted = 0;
  RefusalCounts refusals;  ///< segment verdicts refused, by reason
  CharacterWritingMetrics totals;
};

/// Scores `trace` against `character`. Every scored segment is tried on every reference stroke with
/// `attempt_stroke` (the renderer's reading of a pen-down path): a pair is possible forwards when the
/// attempt writes the stroke, else backwards when it writes it on the reversed path, at a cost of that
/// attempt's mean deviation. Segments and strokes are then paired one to one: as many pairs as possible,
/// and among those the least total mean deviation (an optimal assignment, Kuhn 1955 / Munkres 1957), so a
/// segment that could be either of two strokes goes to the one that leaves the rest best placed. The pairs
/// give the metrics, the order errors and the backwards strokes; each segment's `verdict` gives what the
/// renderer would have said in sequence. Throws InvalidArgument for a bad trace (see validate_pen_trace, and
/// positions too large to convert to data units, more pen-down segments than options.max_segments), a
/// character without strokes, a stroke without elements or
/// without a centre line (placed otherwise than by Scene::lay_out), a placement that is not finite with a
/// positive scale, or options out of range (naming the field).
CharacterScore score_trace(const PlacedCharacter& character, std::span<const PenSample> trace,
                           const ScoreOptions& options = {});

}  // namespace calligraphy
