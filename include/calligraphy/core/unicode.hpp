#pragma once
/// \file unicode.hpp
/// UTF-8 helpers for naming characters. Throws InvalidArgument on malformed UTF-8.
#include <string>
#include <string_view>

namespace calligraphy {

/// Decodes UTF-8 into code points. Throws InvalidArgument naming the byte offset of bad input.
std::u32string decode_utf8(std::string_view text);
/// Encodes one code point as UTF-8. Throws InvalidArgument for surrogates or values > U+10FFFF.
std::string encode_utf8(char32_t code_point);
/// Encodes code points as UTF-8. Throws as the one-code-point form.
std::string encode_utf8(const std::u32string& text);
/// "永 (U+6C38)": how error messages and reports name a character.
std::string describe_character(char32_t code_point);

}  // namespace calligraphy
