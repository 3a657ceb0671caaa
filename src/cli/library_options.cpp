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
    embedded_ = !arguments.option("data");
  }
}

Character CharacterSource::load(char32_t code_point) const {
  if (store_) return store_->load(code_point);
  if (!embedded_) return library_.load(code_point);
  try {
    return library_.load(code_point);
  } catch (const CharacterNotFound& e) {  // the library's message is neutral; the flags are ours
    throw CharacterNotFound(std::string(e.what()) + ": pass --data DIR or --store FILE");
  }
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
