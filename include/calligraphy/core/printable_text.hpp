#pragma once
/// \file printable_text.hpp
/// Text from outside (a file name, a device name, a field of a damaged file) made safe to print on one line
/// of a terminal or a log: an error message is one line that a person can read, whatever it quotes.
#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace calligraphy {

/// The longest error line the command line prints, in bytes (before the note of what was cut).
inline constexpr std::size_t kMaxMessageBytes = 2000;

/// `text` as one printable line of at most about `max_bytes` bytes (+ the note of what was cut):
///  - line breaks and tabs become `\n`, `\r`, `\t`; other C0 controls and DEL become `\xHH` (so an escape
///    sequence cannot move the cursor or recolour the terminal);
///  - C1 controls (U+0080-U+009F) and the Unicode line and paragraph separators (U+2028, U+2029) become
///    `\uHHHH`; a byte that is not part of valid UTF-8 becomes `\xHH`;
///  - every other character is kept as it is (Chinese text stays readable);
///  - past `max_bytes` the text is cut at a character boundary and " ... (N more bytes)" says how much.
/// Never throws but std::bad_alloc.
std::string printable_one_line(std::string_view text, std::size_t max_bytes = kMaxMessageBytes);

/// `text` with each byte that is not part of valid UTF-8 written as the text `\xHH` (lower-case hex, as
/// printable_one_line writes it), everything else kept as it is (line breaks and controls too): how a name in
/// another encoding goes into UTF-8 text such as JSON (json_text.hpp). Valid UTF-8 comes back unchanged.
[[nodiscard]] std::string valid_utf8_text(std::string_view text);

/// `bytes` as lower-case hexadecimal text, two digits a byte, most significant first ({0x0f, 0xa0} ->
/// "0fa0"): how a SHA-256 and a study folder's id are written.
[[nodiscard]] std::string lower_hex(std::span<const unsigned char> bytes);

}  // namespace calligraphy
