#pragma once
// Times of the calendar in UTC as the program writes them: "2024-05-01T12:34:56.789Z" (ISO 8601's extended
// form with a Z, the fraction optional). The one reading of such a text: a schema field of this format and a
// record's time are read by it alike.
#include <string_view>

namespace calligraphy {

/// Seconds since 1970-01-01T00:00:00Z of `iso8601` ("2024-05-01T12:34:56.789Z"; the fraction of one or more
/// digits optional). Throws InvalidArgument quoting the text when it is not such a time: another form, a zone
/// offset, no `Z`, or a day or hour the calendar lacks (2027-02-29, 24:00:01), never read as another day.
double utc_seconds(std::string_view iso8601);

/// The JSON Schema pattern (ECMA-262) of the form `utc_seconds` reads (the calendar's days aside).
inline constexpr std::string_view kUtcTimePattern =
    R"(^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}(\.[0-9]+)?Z$)";

}  // namespace calligraphy
