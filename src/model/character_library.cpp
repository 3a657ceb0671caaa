#include "calligraphy/model/character_library.hpp"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "calligraphy/core/errors.hpp"
#include "core/unicode.hpp"
#include "model/embedded_characters.hpp"

namespace calligraphy {
namespace {

std::string line_column(std::string_view text, std::size_t byte) {
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t i = 0; i < std::min(byte, text.size()); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

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

}  // namespace

CharacterData parse_hanzi_writer_json(std::string_view json, char32_t cp, const std::string& source) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const nlohmann::json::parse_error& e) {
    const std::size_t byte = e.byte > 0 ? e.byte - 1 : 0;
    fail(source, cp, "line:column " + line_column(json, byte),
         "malformed JSON (" + std::string(e.what()) + ")");
  }
  if (!doc.is_object()) fail(source, cp, "/", "expected a JSON object");
  const auto medians = doc.find("medians");
  if (medians == doc.end()) fail(source, cp, "/medians", "missing");
  if (!medians->is_array() || medians->empty()) fail(source, cp, "/medians", "expected a non-empty array");
  CharacterData data;
  data.code_point = cp;
  data.source = source;
  for (std::size_t s = 0; s < medians->size(); ++s) {
    const auto& median = (*medians)[s];
    const std::string stroke_path = "/medians/" + std::to_string(s);
    if (!median.is_array() || median.empty())
      fail(source, cp, stroke_path, "expected a non-empty array of points");
    std::vector<Vec2> points;
    for (std::size_t i = 0; i < median.size(); ++i) {
      const auto& point = median[i];
      const std::string path = stroke_path + "/" + std::to_string(i);
      if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
        fail(source, cp, path, "expected a point [x, y] of two numbers, got " + point.dump());
      }
      const Vec2 p(point[0].get<double>(), point[1].get<double>());
      if (!p.allFinite()) fail(source, cp, path, "point is not finite");
      points.push_back(p);
    }
    data.medians.push_back(std::move(points));
  }
  return data;
}

CharacterLibrary CharacterLibrary::embedded() { return CharacterLibrary{}; }

CharacterLibrary CharacterLibrary::from_directory(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throw DataError(folder.string() +
                    ": character data folder does not exist (fetch it with "
                    "scripts/fetch-hanzi-writer-data.sh)");
  }
  CharacterLibrary library;
  library.folder_ = folder;
  return library;
}

bool CharacterLibrary::contains(char32_t cp) const {
  if (folder_.empty()) return find_embedded(cp) != nullptr;
  std::error_code ec;
  return std::filesystem::is_regular_file(folder_ / (encode_utf8(cp) + ".json"), ec);
}

CharacterData CharacterLibrary::load_data(char32_t cp) const {
  if (folder_.empty()) {
    const auto* e = find_embedded(cp);
    if (e == nullptr) {
      throw CharacterNotFound("character " + describe_character(cp) +
                              " is not in the embedded default set (" +
                              std::to_string(detail::embedded_characters().size()) +
                              " characters); load it from the full hanzi-writer-data package (a folder "
                              "of <char>.json files) or from a corpus store");
    }
    return parse_hanzi_writer_json(e->json, cp, "embedded:" + encode_utf8(cp) + ".json");
  }
  const auto path = folder_ / (encode_utf8(cp) + ".json");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw CharacterNotFound("character " + describe_character(cp) + " not found: no file " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parse_hanzi_writer_json(text.str(), cp, path.string());
}

Character CharacterLibrary::load(char32_t cp, const FitOptions& options) const {
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
  } else {
    for (const auto& entry : std::filesystem::directory_iterator(folder_)) {
      if (entry.path().extension() != ".json") continue;
      try {
        const std::u32string name = decode_utf8(entry.path().stem().string());
        if (name.size() == 1) out.push_back(name[0]);
      } catch (const InvalidArgument&) {
        // Not a character file (package.json, an odd name): skip.
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string CharacterLibrary::description() const {
  if (folder_.empty()) {
    return "embedded default (" + std::to_string(detail::embedded_characters().size()) + " characters)";
  }
  return folder_.string();
}

}  // namespace calligraphy
