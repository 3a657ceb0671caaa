#pragma once
/// \file trace_columns.hpp
/// The one table of a pen trace's columns: each column's name with its SI unit in it ("t_s", "x_m"), the name
/// the trace files give it (the CSV header of `trial_csv` and the HDF5 trace's datasets: "t", "x"), its unit
/// and what it is. Python's DataFrames (`TrialResult.to_dataframe`, `Study.samples`) name their columns by
/// `name`, and what scores a trace (`calligraphy score`, Python's `score`) reads a column by either name.
#include <optional>
#include <span>
#include <string_view>

namespace calligraphy {

struct TraceColumnInfo {
  std::string_view name;       ///< with its unit: "t_s", "x_m", "fx_n"; "state", "stroke" for labels
  std::string_view file_name;  ///< in the CSV header and the HDF5 trace: "t", "x", "fx"
  std::string_view unit;       ///< "s", "m", "N"; empty for labels and counts
  std::string_view doc;        ///< one line
};

/// Every column of a trial's trace, in the CSV's order (t, x, y, z, fx, fy, fz, state, stroke, element,
/// attempt, rewritten).
[[nodiscard]] std::span<const TraceColumnInfo> trace_columns() noexcept;

/// The column `text` names, by its name or its file name; nullopt for any other text.
[[nodiscard]] std::optional<TraceColumnInfo> trace_column(std::string_view text) noexcept;

}  // namespace calligraphy
