#include "calligraphy/report/trace_columns.hpp"

#include <array>

namespace calligraphy {
namespace {

constexpr std::array<TraceColumnInfo, 12> kColumns{{
    {"t_s", "t", "s", "time from the trial's start"},
    {"x_m", "x", "m", "the pen tip as read from the device, x (right on the paper)"},
    {"y_m", "y", "m", "the pen tip, y (up on the paper)"},
    {"z_m", "z", "m", "the pen tip, z (out of the paper)"},
    {"fx_n", "fx", "N", "the commanded force, x"},
    {"fy_n", "fy", "N", "the commanded force, y"},
    {"fz_n", "fz", "N", "the commanded force, z"},
    {"state", "state", "", "the interaction state SS, AS, CS or WS (Wang, Zhang & Yao 2006, Table 1)"},
    {"stroke", "stroke", "", "the active stroke over the scene, counted from 0"},
    {"element", "element", "", "the active element within the stroke, counted from 0"},
    {"attempt", "attempt", "", "the attempt at the stroke, counted from 1; 0 outside any"},
    {"rewritten", "rewritten", "", "1 where the attempt was written again later (not the final writing)"},
}};

}  // namespace

std::span<const TraceColumnInfo> trace_columns() noexcept { return kColumns; }

std::optional<TraceColumnInfo> trace_column(std::string_view text) noexcept {
  for (const TraceColumnInfo& column : kColumns) {
    if (column.name == text || column.file_name == text) return column;
  }
  return std::nullopt;
}

}  // namespace calligraphy
