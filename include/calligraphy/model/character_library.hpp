#pragma once
/// \file character_library.hpp
/// Loads hanzi-writer-data 2.0.1 characters (one `<char>.json` per character, `medians` in a 1024 box,
/// y up, as documented by Make Me a Hanzi) from the embedded default set or from a folder, such as the one
/// `scripts/fetch-hanzi-writer-data.sh` unpacks. Errors name the character, the path and the position.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/fitting.hpp"
#include "calligraphy/model/stroke_outline.hpp"

namespace calligraphy {

/// Bounds on character data. hanzi-writer-data 2.0.1 has 2 to 38 integer points per median inside the
/// 1024 box (y from -124 to 900); these bounds are far above that and keep loading and fitting of hostile
/// files fast (the work is bounded by the file's size, never by its coordinate values).
/// Largest character file read, bytes (hanzi-writer-data files average 5 kB: 47 MB for 9,574).
inline constexpr std::size_t kMaxCharacterFileBytes = std::size_t{16} << 20;
/// Largest |x| or |y| of a median point, data units (about 100 character boxes around the origin).
inline constexpr double kMaxDataCoordinate = 1e5;
/// Most points in one median.
inline constexpr std::size_t kMaxMedianPoints = 10'000;
/// Most strokes (medians) in one character (the most complex encoded CJK characters have about 64).
inline constexpr std::size_t kMaxCharacterStrokes = 128;
/// Most points in all medians of one character together: fitting took up to about 0.15 ms per point on
/// the costliest hostile shapes measured, so this keeps one character's fitting within a few seconds.
inline constexpr std::size_t kMaxCharacterPoints = 20'000;
/// Deepest nesting of JSON arrays and objects (hanzi-writer-data nests 4 deep: object, medians,
/// median, point).
inline constexpr std::size_t kMaxJsonDepth = 16;

/// A character's raw data: one median polyline per stroke, in stroke order, data units.
struct CharacterData {
  char32_t code_point = 0;
  std::string source;  ///< file path, or "embedded:<char>"
  std::vector<std::vector<Vec2>> medians;
};

/// Parses one hanzi-writer-data JSON document: an object whose `medians` is a non-empty array of at
/// most kMaxCharacterStrokes medians, each an array of 2 to kMaxMedianPoints points [x, y] with at least
/// two distinct points and |x|, |y| <= kMaxDataCoordinate, kMaxCharacterPoints points in all, the text
/// at most kMaxCharacterFileBytes; other keys are skipped. `source` names it in errors. Throws DataError
/// naming the source, the character and the position: line:column and the JSON pointer being read for
/// syntax errors, the JSON pointer (such as /medians/2/1/0) for everything else, including numbers out
/// of range (1e400), values of the wrong type, nesting deeper than kMaxJsonDepth and the bounds above.
/// Never recurses on the input's nesting.
CharacterData parse_hanzi_writer_json(std::string_view json, char32_t code_point, const std::string& source);

/// A set of characters to load from. Cheap to copy; loading parses only the character asked for.
class CharacterLibrary {
 public:
  /// The embedded default set: a verbatim subset of hanzi-writer-data 2.0.1 compiled into the library
  /// (data/hanzi-writer-data, Arphic Public License).
  static CharacterLibrary embedded();
  /// The default lookup of the command line, the Python module and the study runner: the embedded
  /// set, and every other character of hanzi-writer-data 2.0.1 (9,574 in all) from the corpus store
  /// compiled into the library (`CorpusStore::bundled()`). An embedded character is fitted from its JSON
  /// file as `embedded()` does; another is loaded from the store as fitted when the store was built
  /// (elements within its quantisation, the medians and the outlines exact). Nothing is read from disk.
  static CharacterLibrary standard();
  /// A folder of `<char>.json` files. Throws DataError when the folder does not exist. Only regular
  /// files of at most kMaxCharacterFileBytes are read (a FIFO or a device named like a character file
  /// is refused without blocking: DataError naming the file).
  static CharacterLibrary from_directory(const std::filesystem::path& folder);

  /// True when the character is available.
  [[nodiscard]] bool contains(char32_t code_point) const;
  /// The raw medians (for a character of the bundled store, its stored medians). Throws
  /// CharacterNotFound (naming the character and where it looked) or DataError; Error (not a DataError)
  /// naming the file when the system will not open it for want of resources (EMFILE, ENFILE, ENOMEM: the
  /// data is not at fault).
  [[nodiscard]] CharacterData load_data(char32_t code_point) const;
  /// The fitted model (elements, feature points, typical IDs). A character of the bundled store is the
  /// stored model, fitted when the store was built (`options` do not apply to it). Throws as `load_data`.
  [[nodiscard]] Character load(char32_t code_point, const FitOptions& options = {}) const;
  /// The filled outlines of the character's strokes, in stroke order: hanzi-writer-data's `strokes` SVG
  /// paths flattened within `tolerance` data units (stroke_outline.hpp), for drawing. Throws as
  /// `load_data`, DataError naming the source, the character and the JSON pointer (/strokes/2) when the
  /// file has no such array or a path does not parse, and InvalidArgument when tolerance is not > 0.
  [[nodiscard]] CharacterOutlines load_outlines(char32_t code_point, double tolerance = 1.0) const;
  /// The outlines as their SVG path data, one per stroke in stroke order (hanzi-writer-data's `strokes`;
  /// for a character of the bundled store, the stored paths). Throws as `load_outlines`.
  [[nodiscard]] std::vector<std::string> load_outline_paths(char32_t code_point) const;
  /// Every available character, sorted by code point. Throws DataError naming the folder when a folder
  /// holds no `<char>.json` file or cannot be listed.
  [[nodiscard]] std::vector<char32_t> characters() const;
  /// "embedded default (58 characters)", the standard set's "every hanzi-writer-data 2.0.1 character
  /// (9574: 58 embedded, the others from the bundled corpus store)", or the folder's path.
  [[nodiscard]] std::string description() const;

 private:
  [[nodiscard]] bool from_bundled_store(char32_t code_point) const;
  struct OutlinePaths {
    std::vector<std::string> paths;
    std::string source;  // where they were read, for errors and CharacterOutlines::source
  };
  [[nodiscard]] OutlinePaths outline_paths(char32_t code_point) const;

  std::filesystem::path folder_;  // empty: embedded
  bool bundled_store_ = false;    // embedded, then the bundled corpus store (standard())
};

class CorpusStore;

/// A corpus store's outline paths of the character (`CorpusStore::load_outline_paths`), one per stroke.
/// Throws as `CorpusStore::load`, and DataError naming the store and the character when it holds none (a
/// store of format 1.0 or 1.1, or built with `corpus build --outlines off`).
[[nodiscard]] std::vector<std::string> store_outline_paths(const CorpusStore& store, char32_t code_point);

/// A character's outlines from its strokes' SVG path data (one path per stroke, in stroke order), each
/// flattened within `tolerance` data units by `parse_svg_path`; `source` names where the paths were read.
/// Throws DataError naming `source`, the character and the JSON pointer (/strokes/2) of a path that does not
/// parse or past which the polygons hold more than kMaxOutlineVertices vertices in all; InvalidArgument for
/// a tolerance not > 0.
[[nodiscard]] CharacterOutlines outlines_from_paths(char32_t code_point, std::span<const std::string> paths,
                                                    const std::string& source, double tolerance = 1.0);

}  // namespace calligraphy
