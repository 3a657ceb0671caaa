#pragma once
// Durations between pen samples, exact to the tick.
#include <cmath>

namespace calligraphy::analysis {

/// `seconds` rounded to whole nanoseconds, the finest resolution of any device clock the library reads. A
/// difference of two sample times is a double's rounding away from the ticks between them (13.075 - 0.002 is
/// 13.072999999999999, not 13.073); rounded, n ticks of 1 ms last exactly n ms, as printed.
[[nodiscard]] inline double whole_nanoseconds(double seconds) {
  const double nanoseconds = std::round(seconds * 1e9);
  // Beyond 2^53 ns (104 days) a double has no whole nanoseconds to round to, and infinities stay as they are.
  return std::abs(nanoseconds) < 9007199254740992.0 ? nanoseconds / 1e9 : seconds;
}

}  // namespace calligraphy::analysis
