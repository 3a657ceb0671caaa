#pragma once
// Shared options: which character library to read (--store FILE, else --data DIR, else the standard set:
// the embedded characters, then the bundled corpus store) and which characters were asked for.
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

class FilePlan;

struct LibraryOptions {
  std::string data_folder;     ///< --data DIR; empty: CharacterLibrary::standard()
  std::string store_file;      ///< --store FILE; empty: none
  bool store_offered = false;  ///< the command has --store (add_library_options), so a hint may name it
};

/// Adds --data DIR and, when `with_store`, --store FILE (the two exclude each other).
void add_library_options(CLI::App& app, LibraryOptions& options, bool with_store);

/// --data DIR, else the standard set (the embedded characters, then the bundled corpus store).
CharacterLibrary library_from(const LibraryOptions& options);

/// Characters from a corpus store (--store FILE: fitted models, each materialised on demand) or else
/// fitted from the library of `library_from`.
class CharacterSource {
 public:
  explicit CharacterSource(const LibraryOptions& options);
  /// The character's model; throws CharacterNotFound (for the embedded set naming --data and --store)
  /// or DataError.
  [[nodiscard]] Character load(char32_t code_point) const;
  /// The model of a character the user named (`named_by`: "CHARS", "--character", "--spec FILE"): as `load`,
  /// but one the library lacks is the user's input, a UsageError (exit 2) starting with `named_by`, as a
  /// protocol's is; one the library has but cannot read stays a DataError (exit 1).
  [[nodiscard]] Character load_named(char32_t code_point, const std::string& named_by) const;
  /// The character's stroke outlines, for drawing (from the store named, else the library). Throws
  /// DataError when there are none (a store built with `corpus build --outlines off`) or as `load`.
  [[nodiscard]] CharacterOutlines load_outlines(char32_t code_point) const;
  /// True when the character is there.
  [[nodiscard]] bool contains(char32_t code_point) const;
  /// Every character there, sorted by code point (DataError for a folder without character files).
  [[nodiscard]] std::vector<char32_t> characters() const;
  /// The store's name and size, or the library's description.
  [[nodiscard]] std::string description() const;

 private:
  std::optional<CorpusStore> store_;
  CharacterLibrary library_;
  bool embedded_ = false;  // the standard set: a missing character gets the --data/--store hint
  bool store_offered_ = false;
};

/// Registers --store FILE and --data DIR (every file in it) as inputs of `plan`: no output may replace them.
void add_library_inputs(FilePlan& plan, const LibraryOptions& options);

/// The code points of a CHARS argument; throws UsageError naming `what` (e.g. "--chars") when it is
/// empty or not UTF-8.
std::u32string characters_from(const std::string& text, const std::string& what);

}  // namespace calligraphy::cli
