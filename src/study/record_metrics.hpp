#pragma once
// A metric of a trial record read by its name in the metric table (analysis/metric_table.hpp). Records
// written before the table name some metrics otherwise (`mean_deviation_mm`, in millimetres): such a record
// is read under the metric's legacy name and scaled back to the metric's unit. Internal to the study module.
#include <optional>
#include <string>
#include <string_view>

#include "calligraphy/analysis/metric_table.hpp"
#include "core/json_reader.hpp"

namespace calligraphy::study_detail {

/// Whether `object` holds metric `info` (null included), under its name or its legacy name.
inline bool contains_metric(const json_detail::JsonView& object, const MetricInfo& info) {
  if (!object.json().is_object()) return false;
  return object.json().contains(std::string(info.name)) ||
         (!info.legacy_name.empty() && object.json().contains(std::string(info.legacy_name)));
}

/// Whether `object` holds metric `name` of the metric table (null included).
inline bool contains_metric(const json_detail::JsonView& object, std::string_view name) {
  return contains_metric(object, metric(name));
}

/// Metric `info` of `object` in its unit; absent when missing or null. A value under the legacy name is
/// multiplied by 1 / legacy_factor (a millimetre value by 1e-3 exactly as before).
inline std::optional<double> record_metric(const json_detail::JsonView& object, const MetricInfo& info) {
  const std::string key(info.name);
  if (object.has(key) || info.legacy_name.empty()) return object.optional_number(key, -1e12, 1e12);
  const std::optional<double> legacy = object.optional_number(std::string(info.legacy_name), -1e12, 1e12);
  return legacy ? std::optional<double>(*legacy * (1.0 / info.legacy_factor)) : std::nullopt;
}

/// Metric `name` of the metric table, read from `object` as record_metric(object, info) does.
inline std::optional<double> record_metric(const json_detail::JsonView& object, std::string_view name) {
  return record_metric(object, metric(name));
}

}  // namespace calligraphy::study_detail
