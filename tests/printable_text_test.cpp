// printable_one_line (include/calligraphy/core/printable_text.hpp): an error message quoting text from
// outside stays one readable line, whatever bytes that text holds.
#include "calligraphy/core/printable_text.hpp"

#include <catch2/catch.hpp>
#include <span>
#include <string>

#include "calligraphy/core/unicode.hpp"

using calligraphy::printable_one_line;

namespace {
bool has_control_byte(const std::string& line) {
  for (const char c : line) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7F) return true;
  }
  return false;
}
}  // namespace

TEST_CASE("line breaks, tabs and terminal escapes are shown escaped, on one line", "[printable]") {
  CHECK(printable_one_line("no haptic device named 'a\nb'") == "no haptic device named 'a\\nb'");
  CHECK(printable_one_line("x\r\ty") == "x\\r\\ty");
  CHECK(printable_one_line("\x1b[31mred\x1b[0m") == "\\x1b[31mred\\x1b[0m");
  CHECK(printable_one_line(std::string("nul\0byte", 8)) == "nul\\x00byte");
  CHECK(printable_one_line("del\x7f") == "del\\x7f");
  // C1 controls (U+009B is a one-code CSI on some terminals) and the Unicode line separators.
  CHECK(printable_one_line("a\xc2\x9b"
                           "b") == "a\\u009bb");
  CHECK(printable_one_line("a\xe2\x80\xa8"
                           "b") == "a\\u2028b");
}

TEST_CASE("Chinese text and other printable characters are kept as they are", "[printable]") {
  CHECK(printable_one_line("永 (U+6C38) is not in the corpus") == "永 (U+6C38) is not in the corpus");
  CHECK(printable_one_line("café \xf0\x9f\x96\x8a") == "café \xf0\x9f\x96\x8a");
}

TEST_CASE("bytes that are not UTF-8 are shown as hexadecimal, one at a time", "[printable]") {
  CHECK(printable_one_line("a\xff"
                           "b") == "a\\xffb");
  CHECK(printable_one_line("\xe6\xb0") == "\\xe6\\xb0");                    // a cut three-byte sequence
  CHECK(printable_one_line("\xc0\xaf") == "\\xc0\\xaf");                    // an overlong '/'
  CHECK(printable_one_line("\xed\xa0\x80") == "\\xed\\xa0\\x80");           // a UTF-16 surrogate
  CHECK(printable_one_line("\xf4\x90\x80\x80") == "\\xf4\\x90\\x80\\x80");  // above U+10FFFF
}

TEST_CASE("a long message is cut at a character boundary and says how much was cut", "[printable]") {
  std::string long_text;
  for (int i = 0; i < 10000; ++i) long_text += "永\n";
  const std::string line = printable_one_line(long_text, 100);
  CHECK_FALSE(has_control_byte(line));
  const auto note = line.find(" ... (");
  REQUIRE(note != std::string::npos);
  CHECK(note <= 100);
  // What was kept is whole characters and escapes: 永 then \n, repeated.
  const std::string kept = line.substr(0, note);
  CHECK(kept.size() % 5 == 0);
  CHECK(kept.substr(0, 5) == "永\\n");
  const std::size_t kept_source_bytes = kept.size() / 5 * 4;
  CHECK(line.substr(note) ==
        " ... (" + std::to_string(long_text.size() - kept_source_bytes) + " more bytes)");
  // Text within the bound is not cut.
  CHECK(printable_one_line(std::string(100, 'a'), 100) == std::string(100, 'a'));
}

TEST_CASE("every single byte becomes printable", "[printable]") {
  for (int byte = 0; byte < 256; ++byte) {
    const std::string line = printable_one_line(std::string(1, static_cast<char>(byte)));
    INFO(byte);
    CHECK_FALSE(has_control_byte(line));
    CHECK_FALSE(line.empty());
  }
}

TEST_CASE("lower_hex writes two lower-case digits a byte, most significant first", "[printable]") {
  const unsigned char bytes[] = {0x00, 0x0f, 0xa0, 0xff, 0x5c};
  CHECK(calligraphy::lower_hex(bytes) == "000fa0ff5c");
  CHECK(calligraphy::lower_hex(std::span<const unsigned char>()).empty());
}

TEST_CASE("a character file's name is a written character: no white space, control or format character",
          "[printable]") {
  for (const char32_t c : {U'永', U'一', U'A', U'\u3400', U'\U00020000'})
    CHECK(calligraphy::names_a_character(c));
  // Controls, white space of every width, and Unicode's format characters (Cf), which print as nothing or
  // turn the rest of a line around (U+202E).
  for (const char32_t c : {U'\x00', U'\x1b', U'\x7f', U'\x85', U' ', U'\t', U'\u00a0', U'\u3000', U'\u00ad',
                           U'\u200b', U'\u200f', U'\u202e', U'\u2066', U'\ufeff', U'\U000e0001'}) {
    INFO(static_cast<unsigned>(c));
    CHECK_FALSE(calligraphy::names_a_character(c));
  }
}
