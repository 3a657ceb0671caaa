#pragma once
/// \file score_report.hpp
/// Reports of a scored pen trace (`score_trace`, trial/score.hpp): a table for people and JSON whose keys
/// follow `trial_json` (trial_report.hpp) where the two share a meaning. What `calligraphy score` prints
/// and writes; definitions of the metrics: docs/metrics.md.
#include <cstddef>
#include <string>

#include "calligraphy/trial/score.hpp"

namespace calligraphy {

/// What was scored, for the reports' header.
struct ScoreDescription {
  std::string character;    ///< UTF-8
  std::string trace;        ///< where the trace came from, e.g. its file name
  std::string units = "m";  ///< units the trace's x and y were given in: "m" or "data"
  std::size_t samples = 0;  ///< samples in the trace
};

/// One row per reference stroke (type, written or not, backwards, mean and max deviation, Frechet and DTW
/// [mm], writing time [s]) and the totals: strokes written, strokes accepted in turn and refusals by reason
/// (the renderer's verdicts), order errors, backwards strokes, pen lifts,
/// deviation, Frechet, DTW [mm], writing, in-air and total time [s], mean speed [m/s], velocity peaks and
/// normalised jerk. Values that do not exist (no stroke matched) print as "-".
std::string score_table(const ScoreDescription& description, const CharacterScore& score);

/// The score as a JSON object (2-space indent, newline-terminated). Keys shared with `trial --json`:
/// `character`, `strokes_total`, `completed_in_order`, `time_s` (first to last pen-down sample [s]),
/// `mean_deviation_mm`, `max_deviation_mm`, `per_stroke` (one object per reference stroke with `index`
/// 1-based, `typical_id`, `mean_deviation_mm`, `max_deviation_mm`, `time_s`). Further keys: `trace`,
/// `units`, `samples`, `strokes_written`, `strokes_in_order`, `order_errors`, `backwards_strokes`,
/// `missing_strokes` (1-based), `strokes_accepted` (segment verdicts accepted), `refusals` (an object with a
/// count per refusal: `too_short`, `backwards`, `wrong_place`, `wrong_stroke`, `wrong_order`),
/// `unmatched_strokes`, `ignored_segments`, `pen_lifts`, `writing_time_s`,
/// `in_air_time_s`, `rms_deviation_mm`, `frechet_mm`, `dtw_mm`, `path_length_mm`, `mean_speed_m_s`,
/// `velocity_peaks`, `normalised_jerk`; per stroke also `written`, `backwards`, `rms_deviation_mm`,
/// `outside_tube_share`, `frechet_mm`, `dtw_mm`, `path_length_mm`, `mean_speed_m_s`, `velocity_peaks`,
/// `normalised_jerk`; `segments`, one object per pen-down segment in writing order: `begin` and `end`
/// (sample indices, 0-based, end exclusive), `ignored`, `matched_stroke` (1-based, null when unmatched),
/// `backwards`, `verdict` (null when ignored or after every stroke was accepted; else `expected_stroke`
/// and `matched_stroke` 1-based, `accepted`, `refusal` ("none" when accepted), `covered_fraction`,
/// `mean_deviation_mm`). A value that does not exist (a stroke not written, no stroke matched) is null.
std::string score_json(const ScoreDescription& description, const CharacterScore& score);

}  // namespace calligraphy
