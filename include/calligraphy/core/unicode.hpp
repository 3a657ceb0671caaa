#pragma once
/// \file unicode.hpp
/// UTF-8 helpers for naming characters. Throws InvalidArgument on malformed UTF-8.
#include <cstddef>
#include <string>
#include <string_view>

namespace calligraphy {

/// Decodes UTF-8 into code points. Throws InvalidArgument naming the byte offset of bad input and showing the
/// bytes at fault as `\xHH` (`malformed UTF-8 at byte 0 (\xe6\xb0): truncated sequence`).
std::u32string decode_utf8(std::string_view text);
/// Encodes one code point as UTF-8. Throws InvalidArgument for surrogates or values > U+10FFFF.
std::string encode_utf8(char32_t code_point);
/// Encodes code points as UTF-8. Throws as the one-code-point form.
std::string encode_utf8(const std::u32string& text);
/// "永 (U+6C38)": how error messages and reports name a character.
std::string describe_character(char32_t code_point);
/// "永 (U+6C38), ︀ (U+FE00)": each code point of `text` named as describe_character names it, so that a
/// mark or a selector that shows as nothing is seen; past `max_characters` the rest are counted ("... (3
/// more)").
std::string describe_characters(const std::u32string& text, std::size_t max_characters = 8);
/// White space as Unicode's White_Space property lists it (PropList.txt, Unicode 15.0): tabs and line ends,
/// the spaces of every width (U+00A0 no-break, U+2000-U+200A, U+3000 ideographic), the line and paragraph
/// separators. A text pasted from a page or a document holds any of them between its characters.
bool is_white_space(char32_t code_point);
/// True for a code point that can name a written character: not white space (above), not a control
/// character (U+0000-U+001F, U+007F-U+009F) and not a format character (Unicode's category Cf: U+200B
/// zero width space, U+202E right-to-left override, U+FEFF, ...). A data folder's file named by anything
/// else is not a character's.
bool names_a_character(char32_t code_point);

}  // namespace calligraphy
