#include "calligraphy/model/character_library.hpp"

#include <algorithm>
#include <system_error>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "model/character_file.hpp"
#include "model/embedded_characters.hpp"
#include "model/median_json_reader.hpp"
#include "model/outline_json_reader.hpp"

namespace calligraphy {
namespace {

[[noreturn]] void fail(const std::string& source, char32_t cp, const std::string& where,
                       const std::string& what) {
  throw DataError(source + ": character " + describe_character(cp) + ": " + where + ": " + what);
}

const detail::EmbeddedCharacter* find_embedded(char32_t cp) {
  const std::string name = encode_utf8(cp);
  for (const auto& e : detail::embedded_characters()) {
    if (name == e.name) return &e;
  }
  return nullptr;
}

struct Document {
  std::string text;
  std::string source;
};

// The JSON text of the character's file: embedded (folder empty) or from the folder.
Document read_document(const std::filesystem::path& folder, char32_t cp) {
  if (folder.empty()) {
    const auto* e = find_embedded(cp);
    if (e == nullptr) {
      throw CharacterNotFound("character " + describe_character(cp) +
                              " is not in the embedded default set (" +
                              std::to_string(detail::embedded_characters().size()) +
                              " characters); load it from the full hanzi-writer-data package (a folder "
                              "of <char>.json files) or from a corpus store");
    }
    return {e->json, "embedded:" + encode_utf8(cp) + ".json"};
  }
  const auto path = folder / (encode_utf8(cp) + ".json");
  return {detail::read_character_file(path, cp, kMaxCharacterFileBytes), path.string()};
}

}  // namespace

CharacterData parse_hanzi_writer_json(std::string_view json, char32_t cp, const std::string& source) {
  if (json.size() > kMaxCharacterFileBytes) {
    fail(source, cp, "/",
         "document of " + std::to_string(json.size()) + " bytes, more than the " +
             std::to_string(kMaxCharacterFileBytes) + " a character file may have");
  }
  detail::MedianJsonResult read = detail::read_medians_json(json);
  if (!read.ok) fail(source, cp, read.where, read.what);
  CharacterData data;
  data.code_point = cp;
  data.source = source;
  data.medians = std::move(read.medians);
  return data;
}

CharacterLibrary CharacterLibrary::embedded() { return CharacterLibrary{}; }

CharacterLibrary CharacterLibrary::standard() {
  CharacterLibrary library;
  library.bundled_store_ = true;
  return library;
}

CharacterLibrary CharacterLibrary::from_directory(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    // Something else by that name (a file, /dev/null) is not a missing folder: say which.
    const bool exists = std::filesystem::exists(folder, ec);
    throw DataError(folder.string() +
                    (exists ? ": not a folder (expected the character data folder, one <character>.json per "
                              "character)"
                            : ": character data folder does not exist (fetch it with "
                              "scripts/fetch-hanzi-writer-data.sh)"));
  }
  CharacterLibrary library;
  library.folder_ = folder;
  return library;
}

bool CharacterLibrary::contains(char32_t cp) const {
  if (folder_.empty())
    return find_embedded(cp) != nullptr || (bundled_store_ && CorpusStore::bundled().contains(cp));
  if (!names_a_character(cp)) return false;  // " .json", a control character's: not a character file
  std::error_code ec;
  return std::filesystem::is_regular_file(folder_ / (encode_utf8(cp) + ".json"), ec);
}

bool CharacterLibrary::from_bundled_store(char32_t cp) const {
  return bundled_store_ && folder_.empty() && find_embedded(cp) == nullptr;
}

CharacterData CharacterLibrary::load_data(char32_t cp) const {
  if (from_bundled_store(cp)) {
    const Character character = CorpusStore::bundled().load(cp);
    CharacterData data;
    data.code_point = cp;
    data.source = character.source;
    for (const Stroke& stroke : character.strokes) data.medians.push_back(stroke.median);
    return data;
  }
  const Document document = read_document(folder_, cp);
  return parse_hanzi_writer_json(document.text, cp, document.source);
}

std::vector<std::string> CharacterLibrary::load_outline_paths(char32_t cp) const {
  return outline_paths(cp).paths;
}

CharacterLibrary::OutlinePaths CharacterLibrary::outline_paths(char32_t cp) const {
  if (from_bundled_store(cp)) {
    const CorpusStore& store = CorpusStore::bundled();
    return {store_outline_paths(store, cp), store.name() + "#" + describe_character(cp)};
  }
  const Document document = read_document(folder_, cp);
  if (document.text.size() > kMaxCharacterFileBytes) {
    fail(document.source, cp, "/", "document larger than a character file may be");
  }
  detail::OutlineJsonResult read = detail::read_outlines_json(document.text);
  if (!read.ok) fail(document.source, cp, read.where, read.what);
  return {std::move(read.paths), document.source};
}

CharacterOutlines CharacterLibrary::load_outlines(char32_t cp, double tolerance) const {
  if (!(tolerance > 0.0)) {
    throw InvalidArgument("load_outlines: tolerance " + shortest_decimal(tolerance) +
                          " must be > 0 data units");
  }
  const OutlinePaths found = outline_paths(cp);
  return outlines_from_paths(cp, found.paths, found.source, tolerance);
}

Character CharacterLibrary::load(char32_t cp, const FitOptions& options) const {
  if (from_bundled_store(cp)) return CorpusStore::bundled().load(cp);
  CharacterData data = load_data(cp);
  try {
    return fit_character(cp, data.medians, data.source, options);
  } catch (const InvalidArgument& e) {
    throw DataError(data.source + ": character " + describe_character(cp) + ": " + e.what());
  }
}

std::vector<char32_t> CharacterLibrary::characters() const {
  std::vector<char32_t> out;
  if (folder_.empty()) {
    for (const auto& e : detail::embedded_characters()) out.push_back(decode_utf8(e.name).at(0));
    if (bundled_store_) {
      for (char32_t cp : CorpusStore::bundled().characters()) {
        if (find_embedded(cp) == nullptr) out.push_back(cp);
      }
    }
  } else {
    std::error_code ec;
    std::filesystem::directory_iterator entries(folder_, ec);
    for (; !ec && entries != std::filesystem::directory_iterator(); entries.increment(ec)) {
      const auto& path = entries->path();
      if (path.extension() != ".json") continue;
      try {
        const std::u32string name = decode_utf8(path.stem().string());
        if (name.size() == 1 && names_a_character(name[0])) out.push_back(name[0]);
      } catch (const InvalidArgument&) {
        // Not a character file (package.json, an odd name): skip.
      }
    }
    if (ec)
      throw DataError(folder_.string() + ": cannot list the character data folder (" + ec.message() + ")");
    if (out.empty()) {
      throw DataError(folder_.string() +
                      ": no character files (<character>.json) in the character data folder "
                      "(fetch hanzi-writer-data with scripts/fetch-hanzi-writer-data.sh)");
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string CharacterLibrary::description() const {
  if (folder_.empty()) {
    const std::string embedded = std::to_string(detail::embedded_characters().size());
    if (bundled_store_) {
      return "every hanzi-writer-data 2.0.1 character (" + std::to_string(characters().size()) + ": " +
             embedded + " embedded, the others from the bundled corpus store)";
    }
    return "embedded default (" + embedded + " characters)";
  }
  return folder_.string();
}

std::vector<std::string> store_outline_paths(const CorpusStore& store, char32_t cp) {
  std::vector<std::string> paths = store.load_outline_paths(cp);
  if (paths.empty()) {
    throw DataError(store.name() + ": character " + describe_character(cp) +
                    ": no stroke outlines (a store built without them, `corpus build --outlines off`)");
  }
  return paths;
}

CharacterOutlines outlines_from_paths(char32_t cp, std::span<const std::string> paths,
                                      const std::string& source, double tolerance) {
  CharacterOutlines outlines;
  outlines.code_point = cp;
  outlines.source = source;
  std::size_t vertices = 0;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    try {
      outlines.strokes.push_back(parse_svg_path(paths[i], tolerance));
    } catch (const DataError& e) {
      fail(source, cp, "/strokes/" + std::to_string(i), e.what());
    }
    for (const OutlinePolygon& polygon : outlines.strokes.back()) vertices += polygon.size();
    if (vertices > kMaxOutlineVertices) {
      fail(source, cp, "/strokes/" + std::to_string(i),
           "more than " + std::to_string(kMaxOutlineVertices) + " outline vertices in all strokes");
    }
  }
  return outlines;
}

}  // namespace calligraphy
