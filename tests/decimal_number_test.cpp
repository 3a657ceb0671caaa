// parse_finite_double (src/core/decimal_number.hpp), the one reading of a decimal number from text that
// options, CSV fields and writer settings share: every finite double is read, subnormal ones included.
#include "calligraphy/core/decimal_number.hpp"

#include <catch2/catch.hpp>
#include <cstdio>
#include <limits>
#include <string>

using calligraphy::parse_finite_double;

TEST_CASE("every finite double is read back from its shortest and its %.17g text", "[decimal]") {
  const double values[] = {0.0, -0.0, 0.5, -3e-4, 1e-310, -1e-310, std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                           -std::numeric_limits<double>::max()};
  for (const double value : values) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", value);
    INFO(text);
    REQUIRE(parse_finite_double(text).has_value());
    CHECK(*parse_finite_double(text) == value);
  }
  CHECK(*parse_finite_double("9.9999999999999694e-311") > 0.0);
}

TEST_CASE("text that is no finite number is refused", "[decimal]") {
  for (const char* text : {"", " 1", "1 ", "+1", "1e999", "-1e999", "1e400", "inf", "-inf", "nan", "0x1p3", "1,5",
                           "--1", "e5", "1e"}) {
    INFO(text);
    CHECK_FALSE(parse_finite_double(text).has_value());
  }
}

TEST_CASE("a value below the smallest subnormal is the zero it rounds to", "[decimal]") {
  REQUIRE(parse_finite_double("1e-400").has_value());
  CHECK(*parse_finite_double("1e-400") == 0.0);
}
