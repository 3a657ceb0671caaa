#include "core/rate_text.hpp"

#include <fmt/format.h>

#include <cmath>

#include "calligraphy/core/servo_rate.hpp"

namespace calligraphy {

std::string servo_rate_range_text(bool real_time) {
  // fmt writes the shortest form that reads back: "[100, 100000] Hz".
  return fmt::format("[{}, {}] Hz", kMinServoRateHz, real_time ? kMaxRealTimeServoRateHz : kMaxServoRateHz);
}

}  // namespace calligraphy

namespace calligraphy::detail {

std::string rate_text(double rate_hz) { return fmt::format("{} Hz", rate_hz); }

std::string measured_rate_text(double rate_hz) {
  if (!std::isfinite(rate_hz)) return rate_text(rate_hz);
  return fmt::format("{} Hz", std::round(rate_hz * 10.0) / 10.0);
}

}  // namespace calligraphy::detail
