// parse_finite_double (src/core/decimal_number.hpp), the one reading of a decimal number from text that
// options, CSV fields and writer settings share: every finite double is read, subnormal ones included; and
// parse_plain_decimal, its fast way for a trace's millions of numbers, to the very double from_chars gives.
#include "calligraphy/core/decimal_number.hpp"

#include <catch2/catch.hpp>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <system_error>
#include <utility>

using calligraphy::parse_finite_double;

TEST_CASE("every finite double is read back from its shortest and its %.17g text", "[decimal]") {
  const double values[] = {0.0,
                           -0.0,
                           0.5,
                           -3e-4,
                           1e-310,
                           -1e-310,
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::max(),
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
  for (const char* text : {"", " 1", "1 ", "+1", "1e999", "-1e999", "1e400", "inf", "-inf", "nan", "0x1p3",
                           "1,5", "--1", "e5", "1e"}) {
    INFO(text);
    CHECK_FALSE(parse_finite_double(text).has_value());
  }
}

TEST_CASE("a value below the smallest subnormal is the zero it rounds to", "[decimal]") {
  REQUIRE(parse_finite_double("1e-400").has_value());
  CHECK(*parse_finite_double("1e-400") == 0.0);
}

namespace {

// The value std::from_chars reads from `text` (correctly rounded, the reference), with its sign for -0.
double reference(const std::string& text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  REQUIRE(error == std::errc());
  REQUIRE(end == text.data() + text.size());
  return value;
}

// The same double, -0 and 0 told apart.
bool same(double a, double b) { return a == b && std::signbit(a) == std::signbit(b); }

}  // namespace

TEST_CASE("a plain decimal reads to the double from_chars gives, for texts of every length and sign",
          "[decimal]") {
  std::mt19937_64 random(20261125);
  std::uniform_int_distribution<int> digit(0, 9), length(0, 17), coin(0, 1);
  for (int k = 0; k < 200000; ++k) {
    // An optional '-', up to 17 integer digits (leading zeros kept), an optional point and up to 17 more.
    std::string text = coin(random) != 0 ? "-" : "";
    const int integer = length(random), fraction = length(random);
    for (int i = 0; i < integer; ++i) text += static_cast<char>('0' + digit(random));
    const bool point = coin(random) != 0 || integer == 0;
    if (point) text += '.';
    for (int i = 0; point && i < fraction; ++i) text += static_cast<char>('0' + digit(random));
    if (integer == 0 && (!point || fraction == 0)) continue;  // no digit: not a number
    INFO(text);
    double plain = 0.0;
    const char* const end = text.data() + text.size();
    const char* const stop = calligraphy::parse_plain_decimal(text.data(), end, plain);
    // At most 15 digits are read here; more are left to from_chars, and either way the value is the same.
    if (integer + (point ? fraction : 0) <= 15) {
      REQUIRE(stop == end);
      CHECK(same(plain, reference(text)));
    } else {
      CHECK(stop == nullptr);
    }
    REQUIRE(parse_finite_double(text).has_value());
    CHECK(same(*parse_finite_double(text), reference(text)));
  }
}

TEST_CASE("a trace's numbers as its writer spells them read back to from_chars' doubles", "[decimal]") {
  // to_chars at the trace's 6, 7 and 4 decimals (trial_report.hpp) of values over the ranges a trace holds.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> metres(-0.2, 0.2), seconds(0.0, 1000.0), newtons(-10.0, 10.0);
  for (int k = 0; k < 100000; ++k) {
    for (const auto& [value, decimals] : {std::pair{seconds(random), 6}, std::pair{metres(random), 7},
                                          std::pair{newtons(random), 4}, std::pair{-0.0, 7}}) {
      char text[64];
      const auto written = std::to_chars(text, text + sizeof text, value, std::chars_format::fixed, decimals);
      const std::string s(text, written.ptr);
      INFO(s);
      double plain = 0.0;
      REQUIRE(calligraphy::parse_plain_decimal(s.data(), s.data() + s.size(), plain) == s.data() + s.size());
      CHECK(same(plain, reference(s)));
    }
  }
}

TEST_CASE("a plain decimal ends where its digits do and refuses what is no plain decimal", "[decimal]") {
  double value = 0.0;
  const std::string row = "0.5,-12.25,7.,.5,1.2.3,1e5,+1,-";
  const char* const end = row.data() + row.size();
  const char* at = calligraphy::parse_plain_decimal(row.data(), end, value);
  REQUIRE(at == row.data() + 3);
  CHECK(value == 0.5);
  at = calligraphy::parse_plain_decimal(at + 1, end, value);
  REQUIRE(at == row.data() + 10);
  CHECK(value == -12.25);
  at = calligraphy::parse_plain_decimal(at + 1, end, value);
  REQUIRE(at == row.data() + 13);  // "7." is 7, as from_chars reads it
  CHECK(value == 7.0);
  at = calligraphy::parse_plain_decimal(at + 1, end, value);
  REQUIRE(at == row.data() + 16);
  CHECK(value == 0.5);
  at = calligraphy::parse_plain_decimal(at + 1, end, value);
  REQUIRE(at == row.data() + 20);  // stops at the second point: the caller sees a field not read to its end
  CHECK(value == 1.2);
  at = calligraphy::parse_plain_decimal(at + 3, end, value);
  REQUIRE(at == row.data() + 24);  // stops at the exponent
  CHECK(value == 1.0);
  for (const char* text : {"", "-", ".", "-.", "+1", " 1", "e5", "1234567890123456"}) {
    INFO(text);
    const std::string s(text);
    CHECK(calligraphy::parse_plain_decimal(s.data(), s.data() + s.size(), value) == nullptr);
  }
}
