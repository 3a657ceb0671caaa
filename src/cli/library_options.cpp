#include "cli/library_options.hpp"

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {

void add_library_options(CLI::App& app, LibraryOptions& options, bool with_store) {
  CLI::Option* data = add_input_path(
      app, "--data", options.data_folder, "DIR",
      "read characters from this hanzi-writer-data folder (one JSON file each)",
      "the embedded characters, then the bundled corpus store (every hanzi-writer-data character)");
  options.store_offered = with_store;
  if (with_store) {
    CLI::Option* store =
        add_input_path(app, "--store", options.store_file, "FILE",
                       "read fitted characters from this corpus store (corpus build)", "none");
    store->excludes(data);
  }
}

void add_library_inputs(FilePlan& plan, const LibraryOptions& options) {
  plan.input("--store", options.store_file);
  plan.input_folder("--data", options.data_folder);
}

CharacterLibrary library_from(const LibraryOptions& options) {
  if (!options.data_folder.empty()) return CharacterLibrary::from_directory(options.data_folder);
  return CharacterLibrary::standard();
}

CharacterSource::CharacterSource(const LibraryOptions& options)
    : library_(CharacterLibrary::standard()), store_offered_(options.store_offered) {
  if (!options.store_file.empty()) {
    store_ = CorpusStore::open(options.store_file);
  } else {
    library_ = library_from(options);
    embedded_ = options.data_folder.empty();
  }
}

CharacterOutlines CharacterSource::load_outlines(char32_t code_point) const {
  if (!store_) return library_.load_outlines(code_point);
  return outlines_from_paths(code_point, store_outline_paths(*store_, code_point),
                             store_->name() + "#" + describe_character(code_point));
}

Character CharacterSource::load(char32_t code_point) const {
  if (store_) return store_->load(code_point);
  if (!embedded_) return library_.load(code_point);
  try {
    return library_.load(code_point);
  } catch (const CharacterNotFound& e) {  // the library's message is neutral; the flags are ours
    throw CharacterNotFound(std::string(e.what()) +
                            (store_offered_ ? ": pass --data DIR or --store FILE" : ": pass --data DIR"));
  }
}

Character CharacterSource::load_named(char32_t code_point, const std::string& named_by) const {
  try {
    return load(code_point);
  } catch (const CharacterNotFound& e) {
    std::string message = named_by;
    throw UsageError(message.append(": ").append(e.what()));
  }
}

bool CharacterSource::contains(char32_t code_point) const {
  return store_ ? store_->contains(code_point) : library_.contains(code_point);
}

std::vector<char32_t> CharacterSource::characters() const {
  return store_ ? store_->characters() : library_.characters();
}

std::string CharacterSource::description() const {
  if (store_)
    return "corpus store " + store_->name() + " (" + std::to_string(store_->size()) + " characters)";
  return library_.description();
}

std::u32string characters_from(const std::string& text, const std::string& what) {
  std::u32string chars;
  try {
    chars = decode_utf8(text);
  } catch (const InvalidArgument& e) {
    throw UsageError(what + ": " + e.what());
  }
  if (chars.empty()) throw UsageError(what + ": no character given");
  return chars;
}

}  // namespace calligraphy::cli
