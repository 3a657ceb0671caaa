#pragma once
// The numbers of the evaluation reports: one value printed as their Markdown tables print it, and the
// nearest-rank percentile their summaries quote (Hyndman & Fan 1996, definition 1: the smallest value with at
// least that share of the values at or below it).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace calligraphy::cli {

/// `value` printed with one printf conversion (`pattern`, e.g. "%.2f" or "%g %%"); at most 63 characters.
inline std::string format_number(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

/// The nearest-rank percentile of `sorted` (ascending) at `fraction` in [0, 1]: its first value at 0; 0 when
/// there is no value.
inline double nearest_rank(const std::vector<double>& sorted, double fraction) {
  if (sorted.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

}  // namespace calligraphy::cli
