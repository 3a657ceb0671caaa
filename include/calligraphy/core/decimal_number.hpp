#pragma once
/// \file decimal_number.hpp
/// Reading a decimal number from text (options, CSV fields, writer settings): one rule for every reader;
/// and writing one back in the fewest digits that read back to it.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace calligraphy {

/// The finite double that the whole of `text` spells ("0.5", "-3e-4", "1e-310"), or nullopt for empty
/// text, trailing characters, "inf", "nan" or a magnitude beyond a double's range (1e999). A value below the
/// smallest normal double is finite: it is kept as the nearest subnormal (or zero), never refused.
[[nodiscard]] std::optional<double> parse_finite_double(std::string_view text);

/// The shortest decimal text that reads back (parse_finite_double) as the same double: "0.1", "1e-05",
/// "0.30000000000000004". Not for the servo path (allocates).
[[nodiscard]] std::string shortest_decimal(double value);

/// A plain decimal ("-0.011845", "2.998", "0": an optional '-', at most 15 digits, at most one '.') at the
/// start of [first, last): sets `value` and returns where it ends; nullptr for anything else (an exponent,
/// more digits), which the caller reads the full way. The digits as an integer and the power of ten are both
/// exact doubles, so one division rounds correctly: the value from_chars gives (Clinger 1990, "How to read
/// floating point numbers accurately", PLDI), in a fraction of its time; a trace has millions of them.
/// Inline, so that a reader's loop over a line's fields holds it.
[[nodiscard]] inline const char* parse_plain_decimal(const char* first, const char* last, double& value) {
  static constexpr double kPowers[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  static constexpr double kSigns[] = {1.0, -1.0};  // a product by -1 is exact, -0 included; no branch
  const bool negative = first != last && *first == '-';
  first += negative ? 1 : 0;
  // The integer digits, then the fraction's, each in a loop of its own (no test for the point at every
  // digit). Beyond 19 digits the unsigned sum wraps; it is then not used.
  const auto is_digit = [](char c) { return static_cast<unsigned char>(c - '0') < 10; };
  std::uint64_t digits = 0;
  const char* const integer = first;
  for (; first != last && is_digit(*first); ++first)
    digits = digits * 10 + static_cast<unsigned>(*first - '0');
  const std::ptrdiff_t integer_digits = first - integer;
  std::ptrdiff_t decimals = 0;
  if (first != last && *first == '.') {
    const char* const fraction = ++first;
    for (; first != last && is_digit(*first); ++first)
      digits = digits * 10 + static_cast<unsigned>(*first - '0');
    decimals = first - fraction;
  }
  const std::ptrdiff_t count = integer_digits + decimals;
  if (count == 0 || count > 15) return nullptr;
  value = static_cast<double>(digits) / kPowers[decimals] * kSigns[negative ? 1 : 0];
  return first;
}

}  // namespace calligraphy
