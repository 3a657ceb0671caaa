#include "calligraphy/core/printable_text.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace calligraphy {
namespace {

// The length of the valid UTF-8 sequence starting at text[i] and its code point, or 0 when the bytes there
// are not one (overlong forms, surrogates and values above U+10FFFF included, as RFC 3629 defines).
std::size_t utf8_sequence(std::string_view text, std::size_t i, char32_t& code_point) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[i + k]); };
  const unsigned char lead = byte(0);
  std::size_t length = 0;
  char32_t value = 0;
  char32_t minimum = 0;
  if (lead < 0x80) {
    code_point = lead;
    return 1;
  } else if ((lead & 0xE0) == 0xC0) {
    length = 2, value = lead & 0x1F, minimum = 0x80;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3, value = lead & 0x0F, minimum = 0x800;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4, value = lead & 0x07, minimum = 0x10000;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return 0;
    value = (value << 6) | (byte(k) & 0x3F);
  }
  if (value < minimum || value > 0x10FFFF || (value >= 0xD800 && value <= 0xDFFF)) return 0;
  code_point = value;
  return length;
}

}  // namespace

std::string printable_one_line(std::string_view text, std::size_t max_bytes) {
  std::string line;
  line.reserve(std::min(text.size(), max_bytes) + 16);
  std::size_t i = 0;
  while (i < text.size()) {
    char32_t code_point = 0;
    const std::size_t length = utf8_sequence(text, i, code_point);
    std::string piece;
    if (length == 0) {
      piece = fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i]));
    } else if (code_point == '\n') {
      piece = "\\n";
    } else if (code_point == '\r') {
      piece = "\\r";
    } else if (code_point == '\t') {
      piece = "\\t";
    } else if (code_point < 0x20 || code_point == 0x7F) {
      piece = fmt::format("\\x{:02x}", static_cast<unsigned>(code_point));
    } else if ((code_point >= 0x80 && code_point <= 0x9F) || code_point == 0x2028 || code_point == 0x2029) {
      piece = fmt::format("\\u{:04x}", static_cast<unsigned>(code_point));
    } else {
      piece.assign(text.substr(i, length));
    }
    if (line.size() + piece.size() > max_bytes) {
      line += fmt::format(" ... ({} more bytes)", text.size() - i);
      return line;
    }
    line += piece;
    i += length == 0 ? 1 : length;
  }
  return line;
}

std::string valid_utf8_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    char32_t code_point = 0;
    const std::size_t length = utf8_sequence(text, i, code_point);
    if (length == 0) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i]));
      ++i;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out;
}

std::string lower_hex(std::span<const unsigned char> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * bytes.size());
  for (const unsigned char b : bytes) {
    out.push_back(kDigits[b >> 4]);
    out.push_back(kDigits[b & 0xF]);
  }
  return out;
}

}  // namespace calligraphy
