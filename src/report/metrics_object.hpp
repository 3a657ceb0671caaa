#pragma once
// The one metrics record (analysis/writing_metrics.hpp) as a JSON object: the keys every report shares
// (docs/metrics.md), named and valued by the metric table (analysis/metric_table.hpp). Internal to the report
// module.
#include <nlohmann/json.hpp>
#include <span>
#include <variant>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"

namespace calligraphy::report_detail {

/// The totals of `metrics` and a "per_character" array, one per-character object each; 0-based indices.
nlohmann::json writing_metrics_object(const WritingMetrics& metrics);

/// A metric's value as JSON: null, a number, an integer or a boolean.
inline nlohmann::json metric_json(const MetricValue& value) {
  if (const auto* number = std::get_if<double>(&value)) return *number;
  if (const auto* count = std::get_if<std::int64_t>(&value)) return *count;
  if (const auto* flag = std::get_if<bool>(&value)) return *flag;
  return nullptr;
}

/// Adds to `object` every metric of `table` reported at `level` (scene, character or stroke), under its name,
/// valued from `of`: a WritingMetrics, a CharacterScore or a StrokeScore.
template <typename Of>
void add_metrics(nlohmann::json& object, MetricLevel level, const Of& of,
                 std::span<const MetricInfo> table = metric_table()) {
  for (const MetricInfo& info : table) {
    if (!info.at(level)) continue;
    MetricValue value;
    if constexpr (std::is_same_v<Of, WritingMetrics>) {
      if (info.of_scene != nullptr) value = info.of_scene(of);
    } else if constexpr (std::is_same_v<Of, CharacterScore>) {
      if (info.of_character != nullptr) value = info.of_character(of);
    } else {
      if (info.of_stroke != nullptr) value = info.of_stroke(of);
    }
    object[std::string(info.name)] = metric_json(value);
  }
}

}  // namespace calligraphy::report_detail
