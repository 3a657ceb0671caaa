#include "calligraphy/core/decimal_number.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace calligraphy {

const char* parse_plain_decimal(const char* first, const char* last, double& value) {
  static constexpr double kPowers[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  const bool negative = first != last && *first == '-';
  if (negative) ++first;
  std::int64_t digits = 0;
  int count = 0, decimals = 0;
  bool point = false;
  for (; first != last; ++first) {
    if (*first >= '0' && *first <= '9') {
      if (++count > 15) return nullptr;
      digits = digits * 10 + (*first - '0');
      decimals += point ? 1 : 0;
    } else if (*first == '.' && !point) {
      point = true;
    } else {
      break;
    }
  }
  if (count == 0) return nullptr;
  value = static_cast<double>(digits) / kPowers[decimals];
  if (negative) value = -value;
  return first;
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
