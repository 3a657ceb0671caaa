#pragma once
// One trial record (trial_record.hpp) as a row of the study's tidy tables (study_tables.hpp), read the same
// for a record saved in a session folder and one a simulated cohort keeps in memory. Internal.
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/study_tables.hpp"

namespace calligraphy::study_detail {

/// The trial's row (without its trace file) from `record`, its session's manifest and its plan; its strokes
/// are appended to `strokes`. The rows' metrics are the study-table columns of `metrics` (the metric table;
/// another only to try a metric added to it). Throws DataError naming `source` and the JSON pointer for a
/// bad record.
TrialRow trial_row(const nlohmann::json& record, const std::string& source, const SessionManifest& manifest,
                   const PlannedTrial& plan, std::vector<StrokeRow>& strokes,
                   std::span<const MetricInfo> metrics = metric_table());

}  // namespace calligraphy::study_detail
