#pragma once
// A rate in a message: "500 Hz", "99.96 Hz" as configured, "678.3 Hz" as measured; never std::to_string's
// "500.000000 Hz". Off the servo path (they allocate).
#include <string>

namespace calligraphy::detail {

/// A configured rate [Hz] as given, in the shortest form that reads back as the same number: "500 Hz".
[[nodiscard]] std::string rate_text(double rate_hz);
/// A measured rate [Hz] to 0.1 Hz, without a trailing ".0": "678.3 Hz", "1000 Hz".
[[nodiscard]] std::string measured_rate_text(double rate_hz);

}  // namespace calligraphy::detail
