#pragma once
/// \file decimal_number.hpp
/// Reading a decimal number from text (options, CSV fields, writer settings): one rule for every reader.
#include <optional>
#include <string_view>

namespace calligraphy {

/// The finite double that the whole of `text` spells ("0.5", "-3e-4", "1e-310"), or nullopt for empty
/// text, trailing characters, "inf", "nan" or a magnitude beyond a double's range (1e999). A value below the
/// smallest normal double is finite: it is kept as the nearest subnormal (or zero), never refused.
[[nodiscard]] std::optional<double> parse_finite_double(std::string_view text);

/// A plain decimal ("-0.011845", "2.998", "0": an optional '-', at most 15 digits, at most one '.') at the
/// start of [first, last): sets `value` and returns where it ends; nullptr for anything else (an exponent,
/// more digits), which the caller reads the full way. The digits as an integer and the power of ten are both
/// exact doubles, so one division rounds correctly: the value from_chars gives (Clinger 1990, "How to read
/// floating point numbers accurately", PLDI), in a fraction of its time; a trace has millions of them.
[[nodiscard]] const char* parse_plain_decimal(const char* first, const char* last, double& value);

}  // namespace calligraphy
