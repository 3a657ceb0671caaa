#pragma once
// One trial record (trial_record.hpp) as a row of the study's tidy tables (study_tables.hpp), read the same
// for a record saved in a session folder and one a simulated cohort keeps in memory. Internal.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/study_tables.hpp"

namespace calligraphy::study_detail {

/// The trial's row (without its trace file) from `record`, its session's manifest and its plan; its strokes
/// are appended to `strokes`. Throws DataError naming `source` and the JSON pointer for a bad record.
TrialRow trial_row(const nlohmann::json& record, const std::string& source, const SessionManifest& manifest,
                   const PlannedTrial& plan, std::vector<StrokeRow>& strokes);

}  // namespace calligraphy::study_detail
