#include "core/rate_text.hpp"

#include <fmt/format.h>

#include <cmath>

namespace calligraphy::detail {

std::string rate_text(double rate_hz) { return fmt::format("{} Hz", rate_hz); }

std::string measured_rate_text(double rate_hz) {
  if (!std::isfinite(rate_hz)) return rate_text(rate_hz);
  return fmt::format("{} Hz", std::round(rate_hz * 10.0) / 10.0);
}

}  // namespace calligraphy::detail
