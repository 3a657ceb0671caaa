#pragma once
// Shared option handling: which character library to read (--data DIR, else the embedded default)
// and which characters were asked for.
#include <string>

#include "calligraphy/character_library.hpp"
#include "cli/arguments.hpp"

namespace calligraphy::cli {

CharacterLibrary library_from(const Arguments& arguments);
/// The code points of a CHARS argument; throws UsageError when empty or not UTF-8.
std::u32string characters_from(const std::string& text);

}  // namespace calligraphy::cli
