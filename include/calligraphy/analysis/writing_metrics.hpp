#pragma once
/// \file writing_metrics.hpp
/// The one definition of what was written: a pen trace (one or many characters) and the scene it was
/// written on give one `WritingMetrics` record. `calligraphy trial`, `calligraphy score`, study sessions,
/// their report and Python all report this record, so one trace gives the same numbers everywhere. Names,
/// units and sources: docs/metrics.md. Indices are 0-based.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// The metrics of a trace against a scene: per character (`score_trace`) and pooled over the scene.
struct WritingMetrics {
  std::vector<CharacterScore> characters;  ///< one per placed character, in scene order
  std::size_t strokes_total = 0;           ///< reference strokes over the scene
  std::size_t strokes_written = 0;         ///< reference strokes matched to a written segment
  /// Segments accepted in turn: the strokes the renderer (and the quiz) would have completed.
  std::size_t strokes_accepted = 0;
  /// Strokes credited assisted in turn (CharacterScore::strokes_assisted), summed over characters.
  std::size_t strokes_assisted = 0;
  std::size_t order_errors = 0;        ///< inversions of the writing order, summed over characters
  std::size_t backwards_strokes = 0;   ///< matched segments written from the stroke's end
  std::size_t unmatched_segments = 0;  ///< scored segments matched to no reference stroke
  RefusalCounts refusals;              ///< segment verdicts refused, by reason
  bool completed_in_order = false;     ///< every character's strokes all written, in order
  /// Deviation [m] pooled over the samples of every matched stroke (every sample weighs the same); absent
  /// when nothing was matched.
  std::optional<DeviationSummary> deviation;
  std::optional<double> frechet_m;  ///< max over matched strokes [m]
  std::optional<double> dtw_m;      ///< mean over matched strokes weighted by their sample counts [m]
  /// First pen-down sample to last pen-down sample [s]; absent when the pen never touched (no such time).
  std::optional<double> total_time_s;
  double pen_down_time_s = 0.0;  ///< sum over pen-down segments of t_last - t_first [s]
  int velocity_peaks = 0;        ///< fluency: velocity peaks summed over scored segments
  /// Fluency: normalised jerk (dimensionless) averaged over scored segments; absent without one.
  std::optional<double> normalised_jerk;
};

/// Scores `trace` against every character of `scene`. Each pen-down run goes to the character whose box
/// (`PlacedCharacter::bounding_box`) holds most of its samples, or, when no box holds any, the character
/// whose box is nearest its first sample; each character's runs are then scored by `score_trace`, with
/// `options` except `start_radius_m`, which is the scene's (`SceneLayout::start_radius_m`). Throws what
/// `score_trace` throws (InvalidArgument naming the sample, the character or the option), and
/// InvalidArgument for a scene without characters.
WritingMetrics writing_metrics(const Scene& scene, std::span<const PenSample> trace,
                               const ScoreOptions& options = {});

}  // namespace calligraphy
