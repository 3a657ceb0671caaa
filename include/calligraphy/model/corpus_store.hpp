#pragma once
/// \file corpus_store.hpp
/// A compact binary store of fitted characters (paper section 3.5: a large number of characters stored
/// compactly as typical-stroke IDs, control points and feature points). The file is read by memory
/// mapping; `CorpusStore::load` materialises one character without parsing the rest. Format (fixed
/// little-endian, CRC-32 checksums, versioned header, sorted index): docs/corpus.md.
///
/// What a stored character holds: per stroke the typical-stroke ID, the elements (kind, degree, control
/// points quantised to 1/steps_per_unit data units, joints shared) and the attraction factors at the
/// feature points (exact float64; a stroke whose factors all equal its typical stroke's default
/// stores none) and, in a 1.1 store written with `CorpusStoreOptions::medians` (the default), the
/// source medians, exactly, which stroke acceptance and scoring follow
/// (docs/stroke-acceptance.md); in a 1.2 store (`CorpusStoreOptions::outlines`, the default, when the
/// outlines are given) also the strokes' outlines for drawing (`load_outline_paths`). A 1.0 store has no
/// medians: a loaded `Stroke::median` is then empty and the centre line is the elements (`StrokeCentreLine`).
/// `Character::source` is
/// "<store path>#<char> (U+XXXX)". Fidelity of the models against the medians is measured when the
/// store is built (`calligraphy corpus fidelity`, docs/corpus.md).
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"

namespace calligraphy {

/// How `write_corpus_store` encodes characters.
struct CorpusStoreOptions {
  /// Quantisation of control points: coordinates are stored as round(x * steps_per_unit), so a control
  /// point moves by at most sqrt(2) / (2 * steps_per_unit) data units, and so does every point of an
  /// element (a Bezier curve is an affine combination of its control points). One of 1, 2, 4, 8, 16.
  int steps_per_unit = 2;
  /// The fitting tolerance the characters were fitted with [data units]; recorded in the header only.
  double fit_tolerance = 10.0;
  /// Also store each stroke's source median (`Stroke::median`), exactly: in units of 1, 1/2 or 1/4 data
  /// unit, the coarsest that holds it (hanzi-writer-data's medians are whole units, in 31 characters
  /// quarter units), else as float64 coordinates (2 strokes of hanzi-writer-data): format 1.1 with the
  /// medians flag. False writes a 1.0 store of the models only, which every 1.x reader reads.
  bool medians = true;
  /// Also store each stroke's outline (hanzi-writer-data's `strokes`: SVG path data, for drawing) where
  /// `encode_corpus_store` is given them: format 1.2 with the outlines flag. A path of absolute M, L, Q, C
  /// and Z commands, one subpath, whole data units within +-1e5 (every path of hanzi-writer-data 2.0.1 but
  /// those of 70 coordinates with decimals) is delta-coded; any other is kept as its text. Either way
  /// `CorpusStore::load_outline_paths` gives back the same numbers, so the outlines flatten to the same
  /// polygons as from the JSON file.
  bool outlines = true;
};

/// What a store's header says, plus sizes.
struct CorpusStoreInfo {
  int version_major = 0;
  int version_minor = 0;
  bool medians = false;   ///< the records hold the strokes' medians (format 1.1, header flag 1)
  bool outlines = false;  ///< the records hold the strokes' outlines where known (format 1.2, header flag 2)
  std::size_t character_count = 0;
  int steps_per_unit = 0;
  double fit_tolerance = 0.0;  ///< data units, as recorded by the writer
  std::size_t file_bytes = 0;
  std::size_t header_bytes = 0;  ///< header and the table of default attraction factors
  std::size_t index_bytes = 0;
  std::size_t record_bytes = 0;
  /// Largest distance a stored control point can be from the one written [data units].
  [[nodiscard]] double max_quantisation_error() const;
};

/// Encodes characters into the store format in memory. Characters are sorted by code point.
/// Throws InvalidArgument for duplicate code points, an empty character, more than 255 strokes, a stroke
/// without elements, a typical ID outside 1-39, degrees outside 1-4, attraction factors not one per
/// feature point, non-finite or out-of-range coordinates (|x| * steps_per_unit > 2^23, a median's
/// coordinate not finite or beyond 2^23 units of its resolution: 2^23 data units when whole, 2^21 in
/// quarter units and as float64), a median of more than 16,383 points, or bad options.
std::vector<std::uint8_t> encode_corpus_store(std::span<const Character> characters,
                                              const CorpusStoreOptions& options = {});
/// The same with each character's outlines: `outline_paths[i]` is `characters[i]`'s, one SVG path per
/// stroke in stroke order, or empty when it has none (`CharacterLibrary::load_outline_paths`); the whole
/// span empty for none at all. Also throws InvalidArgument when the span's size is neither 0 nor the
/// characters', a character's list is neither empty nor one path per stroke, or a path kept as text is
/// longer than 1,048,575 bytes.
std::vector<std::uint8_t> encode_corpus_store(std::span<const Character> characters,
                                              const CorpusStoreOptions& options,
                                              std::span<const std::vector<std::string>> outline_paths);

/// Writes `encode_corpus_store(characters, options)` to `path` with `write_file_atomically`
/// (calligraphy/core/atomic_file.hpp): a temporary file in the same folder, fsync'ed and renamed into
/// place, so that an earlier store is either kept whole or replaced whole and no temporary is left behind.
/// Throws as `encode_corpus_store`, and DataError naming the path when it cannot be written.
void write_corpus_store(const std::filesystem::path& path, std::span<const Character> characters,
                        const CorpusStoreOptions& options = {});
/// The same with each character's outlines, as `encode_corpus_store` takes them.
void write_corpus_store(const std::filesystem::path& path, std::span<const Character> characters,
                        const CorpusStoreOptions& options,
                        std::span<const std::vector<std::string>> outline_paths);

/// A read-only store. Cheap to copy (its bytes are shared); thread-safe for concurrent `load`s.
class CorpusStore {
 public:
  /// Reads the file whole (a store is a few megabytes) and validates the header, the sizes, the index and its
  /// checksum. Records are checked when loaded. Throws DataError naming the file and the offset at fault for
  /// a missing, truncated, corrupted or foreign file, or one larger than 4 GiB (the format's offsets are
  /// 32-bit). The file may change or go once opened: the store keeps what was read.
  static CorpusStore open(const std::filesystem::path& path);
  /// The same over a copy of `bytes` (tests, fuzzing); `name` stands for the file in errors.
  static CorpusStore from_bytes(std::span<const std::uint8_t> bytes, const std::string& name);
  /// The store compiled into the library: every character of hanzi-writer-data 2.0.1 (9,574) fitted by
  /// `calligraphy corpus build` at the default tolerance and quantisation, with the medians and the
  /// outlines (format 1.2), from data/corpus/hanzi-writer-data-2.0.1.clg (Arphic Public License:
  /// data/corpus/ARPHICPL.TXT and NOTICE.md, installed under share/calligraphy/corpus). Checked when first
  /// asked for (header, index and their checksums; each record when loaded, as `open`), then shared, without
  /// a copy. Its `name()` is "bundled:hanzi-writer-data-2.0.1.clg". Throws DataError as `open` if the
  /// compiled-in bytes fail the checks.
  static const CorpusStore& bundled();
  /// SHA-256 of the bundled store's file, lower-case hex (64 characters).
  static const char* bundled_sha256();

  [[nodiscard]] const CorpusStoreInfo& info() const;
  [[nodiscard]] std::size_t size() const { return info().character_count; }
  /// True when the store holds the character. O(log n).
  [[nodiscard]] bool contains(char32_t code_point) const;
  /// Every stored character, sorted by code point.
  [[nodiscard]] std::vector<char32_t> characters() const;
  /// Bytes of the character's record (without its index entry). Throws CharacterNotFound.
  [[nodiscard]] std::size_t record_bytes(char32_t code_point) const;
  /// Materialises one character: binary search in the index, CRC-32 of its record, decoding with every
  /// read bounds-checked. Throws CharacterNotFound (naming the character and the file) or DataError
  /// (naming the file, the character, the record's offset and what is wrong).
  [[nodiscard]] Character load(char32_t code_point) const;
  /// The character's stroke outlines as SVG path data, one per stroke in stroke order, as written
  /// (`CorpusStoreOptions::outlines`); empty when the store (format 1.0 or 1.1) or the character has none.
  /// Throws as `load`.
  [[nodiscard]] std::vector<std::string> load_outline_paths(char32_t code_point) const;
  /// The file's name as used in messages.
  [[nodiscard]] const std::string& name() const;

 private:
  struct Data;
  explicit CorpusStore(std::shared_ptr<const Data> data) : data_(std::move(data)) {}
  std::shared_ptr<const Data> data_;
};

/// Totals over a whole store, every record loaded (so every record checksum verified).
struct CorpusStoreStats {
  std::size_t characters = 0;  ///< characters that loaded
  std::size_t strokes = 0;
  std::size_t elements = 0;
  std::map<int, std::size_t> strokes_by_typical_id;  ///< typical ID 1-39 -> strokes
  std::vector<std::string> errors;                   ///< one DataError message per record that failed
};

/// Loads every character of the store and counts. Bad records are listed in `errors`, not thrown.
CorpusStoreStats corpus_store_stats(const CorpusStore& store);

}  // namespace calligraphy
