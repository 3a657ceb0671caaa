#include "calligraphy/core/unicode.hpp"

#include <cstdio>
#include <utility>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

std::u32string decode_utf8(std::string_view text) {
  std::u32string out;
  std::size_t i = 0;
  // The message shows the bytes at fault as `\xHH` (docs/cli.md: bytes that are not UTF-8 are printed so),
  // from the sequence's first byte through the one that broke it, so that a person sees what was typed or
  // pasted.
  const auto fail = [&](const char* what, std::size_t length) {
    std::string bytes;
    for (std::size_t k = i; k < i + length && k < text.size(); ++k) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned>(static_cast<unsigned char>(text[k])));
      bytes += hex;
    }
    throw InvalidArgument("malformed UTF-8 at byte " + std::to_string(i) + " (" + bytes + "): " + what);
  };
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    int extra = 0;
    char32_t cp = 0;
    if (lead < 0x80) {
      cp = lead;
    } else if ((lead & 0xE0) == 0xC0) {
      extra = 1;
      cp = lead & 0x1F;
    } else if ((lead & 0xF0) == 0xE0) {
      extra = 2;
      cp = lead & 0x0F;
    } else if ((lead & 0xF8) == 0xF0) {
      extra = 3;
      cp = lead & 0x07;
    } else {
      fail("invalid lead byte", 1);
    }
    if (i + static_cast<std::size_t>(extra) >= text.size() && extra > 0)
      fail("truncated sequence", text.size() - i);
    for (int k = 1; k <= extra; ++k) {
      const auto c = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      if ((c & 0xC0) != 0x80) fail("invalid continuation byte", static_cast<std::size_t>(k) + 1);
      cp = (cp << 6) | (c & 0x3F);
    }
    static constexpr char32_t kMinimum[4] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMinimum[extra]) fail("overlong encoding", static_cast<std::size_t>(extra) + 1);
    if (cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      fail("not a Unicode scalar value", static_cast<std::size_t>(extra) + 1);
    out.push_back(cp);
    i += static_cast<std::size_t>(extra) + 1;
  }
  return out;
}

std::string encode_utf8(const std::u32string& text) {
  std::string out;
  for (const char32_t c : text) out += encode_utf8(c);
  return out;
}

std::string encode_utf8(char32_t cp) {
  if (cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
    throw InvalidArgument("encode_utf8: not a Unicode scalar value: " +
                          std::to_string(static_cast<unsigned>(cp)));
  }
  std::string out;
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
  return out;
}

std::string describe_character(char32_t cp) {
  char code[16];
  std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(cp));
  std::string glyph;
  // U+0000 (a JSON string's "\u0000") is named by its code point alone: its byte would end the text of every
  // exception and C string the message passes through, cutting the name off before it.
  try {
    if (cp != 0) glyph = encode_utf8(cp) + " ";
  } catch (const InvalidArgument&) {
  }
  return glyph + "(" + code + ")";
}

std::string describe_characters(const std::u32string& text, std::size_t max_characters) {
  std::string out;
  for (std::size_t k = 0; k < text.size() && k < max_characters; ++k) {
    if (k > 0) out += ", ";
    out += describe_character(text[k]);
  }
  if (text.size() > max_characters)
    out += ", ... (" + std::to_string(text.size() - max_characters) + " more)";
  return out;
}

bool is_white_space(char32_t c) {
  return (c >= U'\x0009' && c <= U'\x000D') || c == U' ' || c == U'\x0085' || c == U'\x00A0' ||
         c == U'\x1680' || (c >= U'\x2000' && c <= U'\x200A') || c == U'\x2028' || c == U'\x2029' ||
         c == U'\x202F' || c == U'\x205F' || c == U'\x3000';
}

namespace {

// Unicode's format characters, general category Cf (DerivedGeneralCategory.txt, Unicode 15.0): invisible,
// and some (U+202E, right-to-left override) turn the text printed after them around.
bool is_format_character(char32_t c) {
  constexpr std::pair<char32_t, char32_t> kFormat[] = {
      {0x00AD, 0x00AD},   {0x0600, 0x0605},   {0x061C, 0x061C},   {0x06DD, 0x06DD},   {0x070F, 0x070F},
      {0x0890, 0x0891},   {0x08E2, 0x08E2},   {0x180E, 0x180E},   {0x200B, 0x200F},   {0x202A, 0x202E},
      {0x2060, 0x2064},   {0x2066, 0x206F},   {0xFEFF, 0xFEFF},   {0xFFF9, 0xFFFB},   {0x110BD, 0x110BD},
      {0x110CD, 0x110CD}, {0x13430, 0x1343F}, {0x1BCA0, 0x1BCA3}, {0x1D173, 0x1D17A}, {0xE0001, 0xE0001},
      {0xE0020, 0xE007F}};
  for (const auto& [first, last] : kFormat) {
    if (c >= first && c <= last) return true;
  }
  return false;
}

}  // namespace

bool names_a_character(char32_t c) {
  const bool control = c < U'\x0020' || (c >= U'\x007F' && c <= U'\x009F');
  return !control && !is_white_space(c) && !is_format_character(c);
}

}  // namespace calligraphy
