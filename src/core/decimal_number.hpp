#pragma once
// Reading a decimal number from text (options, CSV fields, writer settings): one rule for every reader.
// Internal.
#include <optional>
#include <string_view>

namespace calligraphy {

/// The finite double that the whole of `text` spells ("0.5", "-3e-4", "1e-310"), or nullopt for empty
/// text, trailing characters, "inf", "nan" or a magnitude beyond a double's range (1e999). A value below the
/// smallest normal double is finite: it is kept as the nearest subnormal (or zero), never refused.
[[nodiscard]] std::optional<double> parse_finite_double(std::string_view text);

}  // namespace calligraphy
