#include "cli/library_options.hpp"

#include "calligraphy/core/errors.hpp"
#include "core/unicode.hpp"

namespace calligraphy::cli {

CharacterLibrary library_from(const Arguments& arguments) {
  if (const auto folder = arguments.option("data")) return CharacterLibrary::from_directory(*folder);
  return CharacterLibrary::embedded();
}

CharacterSource::CharacterSource(const Arguments& arguments) : library_(CharacterLibrary::embedded()) {
  if (const auto path = arguments.option("store")) {
    store_ = CorpusStore::open(*path);
  } else {
    library_ = library_from(arguments);
  }
}

Character CharacterSource::load(char32_t code_point) const {
  return store_ ? store_->load(code_point) : library_.load(code_point);
}

std::u32string characters_from(const std::string& text) {
  std::u32string chars;
  try {
    chars = decode_utf8(text);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("characters: ") + e.what());
  }
  if (chars.empty()) throw UsageError("no character given");
  return chars;
}

}  // namespace calligraphy::cli
