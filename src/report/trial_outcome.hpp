#pragma once
// The part of a trial's JSON record that every record holds, the CLI's (`trial_json`, trial_report.hpp) and a
// study's (study/trial_record.hpp) alike: each adds its own fields to this one object and writes it once.
// Internal.
#include <nlohmann/json.hpp>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy::report_detail {

/// The value of the run-level metric `info` (metric_level_run of the metric table) from the renderer's
/// figures; null for a metric that is not the run's.
MetricValue run_metric_value(const MetricInfo& info, const TrialMetrics& metrics);

/// How the trial ended (`end_reason`, `aborted`, `abort_reason`), the renderer's figures
/// (the metric table's run level: `strokes_completed`, `strokes_assisted`, `trial_time_s` [s], `max_force_n`,
/// ...) and every key of the one metrics record `writing` (metrics_object.hpp).
nlohmann::json trial_outcome_object(const TrialResult& result, const WritingMetrics& writing);

/// The renderer's view of one stroke: `index`, `character`, `typical_id`, `completed` (in turn) and
/// `attempts`; what was written is the metrics record's.
nlohmann::json renderer_stroke_object(const StrokeMetrics& stroke);

}  // namespace calligraphy::report_detail
