#pragma once
// The embedded default character set, generated at build time from data/hanzi-writer-data.
#include <span>

namespace calligraphy::detail {

struct EmbeddedCharacter {
  const char* name;  ///< the character, UTF-8
  const char* json;  ///< the verbatim hanzi-writer-data JSON text
};

std::span<const EmbeddedCharacter> embedded_characters();

}  // namespace calligraphy::detail
