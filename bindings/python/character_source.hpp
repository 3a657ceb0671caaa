#pragma once
// What Python's `CharacterLibrary` is: the standard set (the embedded characters, then the corpus store
// compiled into the library: every hanzi-writer-data character), a folder of hanzi-writer-data files
// (both fitted on load, model/character_library.hpp) or a binary corpus store of fitted characters
// (model/corpus_store.hpp). Cheap to copy.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"

namespace calligraphy::python {

class CharacterSource {
 public:
  /// The standard set: the embedded characters, then the bundled corpus store (every character).
  static CharacterSource embedded();
  /// The 58 embedded characters only.
  static CharacterSource embedded_only();
  static CharacterSource hanzi_writer_folder(const std::filesystem::path& folder);
  static CharacterSource store(const std::filesystem::path& path);

  /// Throws CharacterNotFound (for the embedded set saying how to load more from Python) or DataError.
  [[nodiscard]] Character load(char32_t code_point) const;
  [[nodiscard]] bool contains(char32_t code_point) const;
  [[nodiscard]] std::vector<char32_t> characters() const;
  [[nodiscard]] std::string description() const;
  [[nodiscard]] const std::optional<CorpusStore>& corpus_store() const { return store_; }

 private:
  CharacterLibrary library_ = CharacterLibrary::standard();
  std::optional<CorpusStore> store_;
  bool embedded_ = true;
};

/// The one code point of a one-character str; InvalidArgument naming `name` otherwise.
char32_t one_character(const std::string& text, const std::string& name);

}  // namespace calligraphy::python
