#pragma once
/// \file score_report.hpp
/// Reports of a scored pen trace (`writing_metrics`, analysis/writing_metrics.hpp): a table for people and
/// the one metrics record as JSON, which `trial_json` (trial_report.hpp) and study records also carry. What
/// `calligraphy score` prints and writes; definitions of the metrics: docs/metrics.md.
#include <cstddef>
#include <string>

#include "calligraphy/analysis/writing_metrics.hpp"

namespace calligraphy {

/// What was scored, for the reports' header.
struct ScoreDescription {
  std::string character;    ///< the characters scored, UTF-8
  std::string trace;        ///< where the trace came from, e.g. its file name
  std::string units = "m";  ///< units the trace's x and y were given in: "m" or "data"
  std::size_t samples = 0;  ///< samples in the trace
};

/// A table for people. Per character, one row per reference stroke, numbered from 1 (the JSON counts from 0):
/// type, the mean and max deviation, Frechet and DTW [mm] and writing time [s] of the segment matched to it,
/// and one verdict from the renderer's verdicts in writing order: "accepted" (in turn), "refused: REASON"
/// with how far the refused pen-down was from the stroke due ("refused: wrong place (4.0 mm off)"; a wrong
/// order or a wrong stroke is the verdict of the stroke the pen wrote), or "not written". Then its totals:
/// strokes accepted, refused (by reason) and not written, which add up to the strokes; pen-downs refused by
/// reason (the JSON's `refusals`), unmatched and too short; the strokes matched, and the deviation, Frechet,
/// DTW [mm], writing, in-air and total time [s], mean speed [m/s], velocity peaks and normalised jerk they
/// pool; then, for several characters, the scene's totals. Values that do not exist (no stroke matched)
/// print as "-".
std::string score_table(const ScoreDescription& description, const WritingMetrics& metrics);

/// The one metrics record (writing_metrics.hpp) as a JSON object (2-space indent, newline-terminated), the
/// keys docs/metrics.md lists: the scene's totals (every metric of the metric table at the scene level,
/// analysis/metric_table.hpp, under its name and in its SI unit, and `refusals`) and `per_character`, one
/// object per character with its own metrics, `refusals`, `missing_strokes`, `per_stroke` (each stroke's
/// metrics) and `segments`. Every index is 0-based; a value that does not exist (nothing
/// matched) is null. `calligraphy trial --json`, `calligraphy score --json`, study trial records and Python
/// all carry these keys with these values.
std::string writing_metrics_json(const WritingMetrics& metrics);

/// `{"character", "trace", "units", "samples"}` of `description` and every key of `writing_metrics_json`.
std::string score_json(const ScoreDescription& description, const WritingMetrics& metrics);

}  // namespace calligraphy
