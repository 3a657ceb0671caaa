#include "core/utc_time.hpp"

#include <ctime>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

double utc_seconds(std::string_view iso8601) {
  // YYYY-MM-DDTHH:MM:SS, an optional fraction of one or more digits, then Z: a time of the calendar (a day
  // its month has, 2028-02-29 but not 2027-02-29; hours 00-23, minutes 00-59, seconds 00-59, or 60 as a leap
  // second at 23:59 of a month's last day), never normalised into another (timegm would read 2027-02-29 as
  // 2027-03-01).
  const auto fail = [&iso8601]() -> double {
    throw InvalidArgument(
        "'" + std::string(iso8601) +
        "' is not a UTC time like 2024-05-01T12:34:56.789Z (a day of the calendar, in UTC)");
  };
  const auto digits = [&iso8601](std::size_t at, std::size_t count, int& value) {
    value = 0;
    for (std::size_t i = at; i < at + count; ++i) {
      if (i >= iso8601.size() || iso8601[i] < '0' || iso8601[i] > '9') return false;
      value = value * 10 + (iso8601[i] - '0');
    }
    return true;
  };
  const auto at = [&iso8601](std::size_t i, char c) { return i < iso8601.size() && iso8601[i] == c; };
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!digits(0, 4, year) || !at(4, '-') || !digits(5, 2, month) || !at(7, '-') || !digits(8, 2, day) ||
      !at(10, 'T') || !digits(11, 2, hour) || !at(13, ':') || !digits(14, 2, minute) || !at(16, ':') ||
      !digits(17, 2, second)) {
    return fail();
  }
  std::size_t next = 19;
  double fraction = 0.0;
  if (at(next, '.')) {
    double scale = 0.1;
    ++next;
    const std::size_t first = next;
    while (next < iso8601.size() && iso8601[next] >= '0' && iso8601[next] <= '9') {
      fraction += scale * (iso8601[next] - '0');
      scale /= 10.0;
      ++next;
    }
    if (next == first) return fail();
  }
  if (!at(next, 'Z') || next + 1 != iso8601.size()) return fail();
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  static constexpr int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month < 1 || month > 12 || day < 1 || day > kDays[month - 1] + (month == 2 && leap ? 1 : 0) ||
      hour > 23 || minute > 59 || second > 60) {
    return fail();
  }
  // A leap second is the last second of a month's last day, 23:59:60 (RFC 3339, section 5.7): second 60 at
  // any other time is a time the calendar lacks.
  const int last_day = kDays[month - 1] + (month == 2 && leap ? 1 : 0);
  if (second == 60 && (day != last_day || hour != 23 || minute != 59)) return fail();
  std::tm utc{};
  utc.tm_year = year - 1900;
  utc.tm_mon = month - 1;
  utc.tm_mday = day;
  utc.tm_hour = hour;
  utc.tm_min = minute;
  utc.tm_sec = second;
  return static_cast<double>(timegm(&utc)) + fraction;
}

}  // namespace calligraphy
