#include "calligraphy/core/decimal_number.hpp"

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace calligraphy {

std::string shortest_decimal(double value) {
  char text[32];  // a double's shortest form needs at most 24 characters
  return std::string(text, std::to_chars(text, text + sizeof text, value).ptr);
}

std::optional<double> parse_finite_double(std::string_view text) {
  double value = 0.0;
  const char* last = text.data() + text.size();
  if (parse_plain_decimal(text.data(), last, value) == last) return value;  // the common case
  const auto [end, error] = std::from_chars(text.data(), last, value, std::chars_format::general);
  if (text.empty() || end != last) return std::nullopt;
  if (error == std::errc::result_out_of_range) {
    // Beyond a double at either end: an overflow (1e999) is refused, an underflow (1e-400) is the finite
    // value it rounds to. strtod tells the two apart (it returns HUGE_VAL only for an overflow).
    const double rounded = std::strtod(std::string(text).c_str(), nullptr);
    if (!std::isfinite(rounded)) return std::nullopt;
    return rounded;
  }
  if (error != std::errc() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace calligraphy
