#pragma once
/// \file character_library.hpp
/// Loads hanzi-writer-data 2.0.1 characters (one `<char>.json` per character, `medians` in a 1024 box,
/// y up, as documented by Make Me a Hanzi) from the embedded default set or from a folder, such as the one
/// `scripts/fetch-hanzi-writer-data.sh` unpacks. Errors name the character, the path and the position.
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/fitting.hpp"

namespace calligraphy {

/// A character's raw data: one median polyline per stroke, in stroke order, data units.
struct CharacterData {
  char32_t code_point = 0;
  std::string source;  ///< file path, or "embedded:<char>"
  std::vector<std::vector<Vec2>> medians;
};

/// Parses one hanzi-writer-data JSON document. `source` names it in errors. Throws DataError naming
/// the source, the character and the position (line:column for syntax errors, a JSON pointer such as
/// /medians/2/1 for structural ones).
CharacterData parse_hanzi_writer_json(std::string_view json, char32_t code_point, const std::string& source);

/// A set of characters to load from. Cheap to copy; loading parses only the character asked for.
class CharacterLibrary {
 public:
  /// The embedded default set: a verbatim subset of hanzi-writer-data 2.0.1 compiled into the library
  /// (data/hanzi-writer-data, Arphic Public License).
  static CharacterLibrary embedded();
  /// A folder of `<char>.json` files. Throws DataError when the folder does not exist.
  static CharacterLibrary from_directory(const std::filesystem::path& folder);

  /// True when the character is available.
  [[nodiscard]] bool contains(char32_t code_point) const;
  /// The raw medians. Throws CharacterNotFound (naming the character and where it looked) or DataError.
  [[nodiscard]] CharacterData load_data(char32_t code_point) const;
  /// The fitted model (elements, feature points, typical IDs). Throws as `load_data`.
  [[nodiscard]] Character load(char32_t code_point, const FitOptions& options = {}) const;
  /// Every available character, sorted by code point.
  [[nodiscard]] std::vector<char32_t> characters() const;
  /// "embedded default (58 characters)" or the folder's path.
  [[nodiscard]] std::string description() const;

 private:
  std::filesystem::path folder_;  // empty: embedded
};

}  // namespace calligraphy
