#pragma once
// Shared option handling: which character library to read (--store FILE, else --data DIR, else the
// embedded default) and which characters were asked for.
#include <optional>
#include <string>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "cli/arguments.hpp"

namespace calligraphy::cli {

CharacterLibrary library_from(const Arguments& arguments);

/// Characters from a corpus store (--store FILE: fitted models, each materialised on demand) or else
/// fitted from the library of `library_from`.
class CharacterSource {
 public:
  explicit CharacterSource(const Arguments& arguments);
  /// The character's model; throws CharacterNotFound (for the embedded set naming --data and --store)
  /// or DataError.
  [[nodiscard]] Character load(char32_t code_point) const;

 private:
  std::optional<CorpusStore> store_;
  CharacterLibrary library_;
  bool embedded_ = false;  // the embedded default set: a missing character gets the --data hint
};
/// The code points of a CHARS argument; throws UsageError when empty or not UTF-8.
std::u32string characters_from(const std::string& text);

}  // namespace calligraphy::cli
