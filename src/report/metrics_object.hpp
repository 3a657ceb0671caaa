#pragma once
// The one metrics record (analysis/writing_metrics.hpp) as a JSON object: the keys every report shares
// (docs/metrics.md). Internal to the report module.
#include <nlohmann/json.hpp>

#include "calligraphy/analysis/writing_metrics.hpp"

namespace calligraphy::report_detail {

/// The totals of `metrics` and a "per_character" array, one per-character object each; 0-based indices.
nlohmann::json writing_metrics_object(const WritingMetrics& metrics);

}  // namespace calligraphy::report_detail
