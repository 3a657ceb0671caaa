#include "character_source.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy::python {

CharacterSource CharacterSource::embedded() { return {}; }

CharacterSource CharacterSource::embedded_only() {
  CharacterSource source;
  source.library_ = CharacterLibrary::embedded();
  return source;
}

CharacterSource CharacterSource::hanzi_writer_folder(const std::filesystem::path& folder) {
  CharacterSource source;
  source.library_ = CharacterLibrary::from_directory(folder);
  source.embedded_ = false;
  return source;
}

CharacterSource CharacterSource::store(const std::filesystem::path& path) {
  CharacterSource source;
  source.store_ = CorpusStore::open(path);
  source.embedded_ = false;
  return source;
}

Character CharacterSource::load(char32_t code_point) const {
  if (store_) return store_->load(code_point);
  if (!embedded_) return library_.load(code_point);
  try {
    return library_.load(code_point);
  } catch (const CharacterNotFound& e) {
    throw CharacterNotFound(
        std::string(e.what()) +
        " (CharacterLibrary.from_hanzi_writer(folder) or CharacterLibrary.from_store(path))");
  }
}

bool CharacterSource::contains(char32_t code_point) const {
  return store_ ? store_->contains(code_point) : library_.contains(code_point);
}

std::vector<char32_t> CharacterSource::characters() const {
  return store_ ? store_->characters() : library_.characters();
}

std::string CharacterSource::description() const {
  if (store_) {
    return "corpus store " + store_->name() + " (" + std::to_string(store_->size()) + " characters)";
  }
  return library_.description();
}

char32_t one_character(const std::string& text, const std::string& name) {
  const std::u32string chars = decode_utf8(text);
  if (chars.size() != 1) {
    throw InvalidArgument(
        name + ": expected exactly one character, got " + std::to_string(chars.size()) +
        (chars.empty() ? std::string(" (an empty string)") : ": " + describe_characters(chars)));
  }
  return chars[0];
}

}  // namespace calligraphy::python
