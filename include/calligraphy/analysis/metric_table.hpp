#pragma once
/// \file metric_table.hpp
/// The one table of a trial's results: every metric with its one name (the SI unit in it: "mean_deviation_m",
/// "frechet_m", "total_time_s"), its unit, one line of doc, how it is computed and where that comes from, the
/// levels it is reported at (the scene's totals, each character, each reference stroke; the live run of a
/// trial) and, for a metric that had another name before, that name and its scale. From it and from nothing
/// else come the metric keys of the one metrics record (`writing_metrics_json`, so `calligraphy trial
/// --json`, `calligraphy score --json`, trial and study records), the study tables' metric columns, the
/// Python names and `calligraphy schema metrics` (docs/metrics.md's table). Definitions: docs/metrics.md.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "calligraphy/analysis/writing_metrics.hpp"

namespace calligraphy {

/// Where a metric is reported; a metric may be reported at several (a bit set).
enum MetricLevel : std::uint8_t {
  metric_level_scene = 1,      ///< the totals of the whole trace (the record's top level)
  metric_level_character = 2,  ///< each character (`per_character`)
  metric_level_stroke = 4,     ///< each reference stroke of a character (`per_stroke`)
  /// the live run of a trial as the renderer saw it (`calligraphy trial --json`, trial and study records),
  /// beside the scene's totals: filled by the trial's report, not from a trace
  metric_level_run = 8,
};

/// What a metric's value is, and so its JSON type.
enum class MetricKind : std::uint8_t {
  number,  ///< a real number in `unit` (JSON number); null where it does not exist (nothing matched)
  count,   ///< a whole number (JSON integer)
  flag,    ///< true or false (JSON boolean)
};

/// A table of a study (study_tables.hpp) a metric can be a column of.
enum class StudyTable : std::uint8_t {
  trials,   ///< trials.csv: one row per saved trial, the record's top-level value (scene or run level)
  strokes,  ///< strokes.csv: one row per reference stroke, the stroke's value (stroke level)
};

/// What a study table (study_tables.hpp) reads for a metric a trial record lacks.
enum class MetricMissing : std::uint8_t {
  null,     ///< nothing (an empty field): a record written before the metric was kept
  zero,     ///< 0, or false for a flag: what the metric was before it was kept (no assisted stroke before the
            ///< assisted credit)
  refused,  ///< none: the record is damaged (a DataError naming the file and key); the scoring's totals are
            ///< in every record
};

/// A metric's value: nothing (JSON null), a number, a count or a flag.
using MetricValue = std::variant<std::monostate, double, std::int64_t, bool>;

/// One metric.
struct MetricInfo {
  std::string_view name = {};  ///< the one name, SI unit in it: key, CSV column, Python name
  MetricKind kind = MetricKind::number;
  std::string_view unit = {};        ///< SI ("m", "s", "m/s", "N"); empty for counts, flags and ratios
  std::string_view doc = {};         ///< one line: what the value is
  std::string_view definition = {};  ///< how it is computed: the function or the formula
  std::string_view source = {};      ///< the paper or standard the definition comes from; may be empty
  std::uint8_t levels = 0;           ///< MetricLevel bits
  /// The name records and Python used before, in another unit (records older than the metric table, Python
  /// for one version with a DeprecationWarning); empty when the name never changed.
  std::string_view legacy_name = {};
  double legacy_factor = 1.0;  ///< value under legacy_name = value x legacy_factor (1000 for mm)
  /// The value at each level (null when the metric is not reported there). Stroke: the reference stroke.
  MetricValue (*of_scene)(const WritingMetrics&) = nullptr;
  MetricValue (*of_character)(const CharacterScore&) = nullptr;
  MetricValue (*of_stroke)(const StrokeScore&) = nullptr;
  /// Its place among the metric columns of the study tables (study_tables.hpp), counted from 1: of
  /// trials.csv (a metric at the scene or run level) and of strokes.csv (a metric at the stroke level); 0
  /// when it is not a column of that table. The CSV headers, the rows read back and Python's DataFrames
  /// follow these places, so a column keeps its place when a metric is added.
  std::uint8_t trials_column = 0;
  std::uint8_t strokes_column = 0;
  /// What the study tables read when a record lacks it (the default suits a metric added later).
  MetricMissing if_missing = MetricMissing::null;

  [[nodiscard]] constexpr bool at(MetricLevel level) const noexcept { return (levels & level) != 0; }
  /// Its place among the metric columns of `table`; 0 when it is not one of them.
  [[nodiscard]] constexpr std::uint8_t column(StudyTable table) const noexcept {
    return table == StudyTable::trials ? trials_column : strokes_column;
  }
};

/// Every metric, in the order docs/metrics.md lists them.
[[nodiscard]] std::span<const MetricInfo> metric_table() noexcept;

/// The metrics of `table` that are columns of study table `which`, in their columns' order.
[[nodiscard]] std::vector<MetricInfo> study_metric_columns(
    StudyTable which, std::span<const MetricInfo> table = metric_table());

/// One row's values of a study table's metric columns, in the columns' order, read by the metric's name.
class MetricValues {
 public:
  MetricValues() = default;
  /// Every metric column of `which` in `table`, without a value yet: a number null, a count 0, a flag false.
  explicit MetricValues(StudyTable which, std::span<const MetricInfo> table = metric_table());

  /// The value of metric `name`. InvalidArgument naming it when the row has no such column.
  [[nodiscard]] const MetricValue& at(std::string_view name) const;
  /// Metric `name` as a number (a count as its value, a flag as 0 or 1); nullopt when null.
  /// InvalidArgument naming it when the row has no such column.
  [[nodiscard]] std::optional<double> number(std::string_view name) const;
  /// Sets metric `name`. InvalidArgument naming it when the row has no such column.
  void set(std::string_view name, MetricValue value);

  /// The columns' metric names, and their values in the same order.
  [[nodiscard]] std::span<const std::string_view> names() const noexcept { return names_; }
  [[nodiscard]] std::span<const MetricValue> values() const noexcept { return values_; }

 private:
  [[nodiscard]] std::size_t index(std::string_view name) const;

  std::vector<std::string_view> names_;  // the table's names: text with static storage
  std::vector<MetricValue> values_;
};

/// The metric of `table` called `text`, by its name or its legacy name; nullopt for any other text.
[[nodiscard]] std::optional<MetricInfo> find_metric(
    std::string_view text, std::span<const MetricInfo> table = metric_table()) noexcept;

/// The metric called `name` in the metric table: its name, for code that writes a metric the table holds
/// (a renderer's figure, a report's row). InvalidArgument when the table has no such metric.
[[nodiscard]] const MetricInfo& metric(std::string_view name);

/// The levels of `levels` (MetricLevel bits) as text: "scene, character, stroke".
[[nodiscard]] std::string metric_levels_text(std::uint8_t levels);

/// `table` as a Markdown table for the documentation: metric, unit, levels, what it is, how it is computed
/// (with its source), the name before.
[[nodiscard]] std::string metric_markdown(std::span<const MetricInfo> table = metric_table());

/// The JSON Schema (draft 2020-12) of the metric keys of a record at `level` (one MetricLevel bit): each
/// metric a property with its type ("number" or null, "integer", "boolean") and description ("doc [unit]").
[[nodiscard]] std::string metric_json_schema(MetricLevel level,
                                             std::span<const MetricInfo> table = metric_table());

}  // namespace calligraphy
