// `calligraphy characters [--strokes N] [--typical STROKE] [--text TEXT] [--json]`: the characters the
// library holds (by default every hanzi-writer-data character: the embedded ones and the bundled corpus
// store), all of them or those with N strokes, with a typical stroke, or of a text; filters combine.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/suggest.hpp"

namespace calligraphy::cli {
namespace {

struct CharactersCommand {
  std::int64_t strokes = 0;  // 0: any count
  std::string typical;
  std::string text;
  bool json = false;
  LibraryOptions library;
};

std::string upper(std::string text) {
  for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

// The typical stroke --typical names: its ID (1-39), acronym (any case), Chinese name or CJK stroke
// character; a UsageError naming the option and close acronyms otherwise.
int typical_id_from(const std::string& value) {
  if (!value.empty() &&
      std::all_of(value.begin(), value.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const int id = value.size() <= 2 ? std::stoi(value) : 0;
    if (id < 1 || id > static_cast<int>(typical_strokes().size()))
      throw UsageError("--typical " + value +
                       ": a typical stroke ID is 1-39 (calligraphy strokes lists them)");
    return id;
  }
  if (const auto id = typical_stroke_id_by_name(value)) return *id;
  std::vector<std::string> acronyms;
  for (const TypicalStroke& t : typical_strokes()) acronyms.emplace_back(t.acronym);
  std::string message = "--typical " + value +
                        ": no typical stroke has this ID (1-39), acronym (HZG), name (横折钩) or stroke "
                        "character (calligraphy strokes lists them)";
  const std::vector<std::string> close = close_names(upper(value), acronyms);
  for (std::size_t i = 0; i < close.size(); ++i)
    message += (i == 0 ? "; did you mean '" : i + 1 == close.size() ? "' or '" : "', '") + close[i];
  if (!close.empty()) message += "'?";
  throw UsageError(message);
}

std::string code_point_text(char32_t c) {
  char text[16];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(c));
  return text;
}

struct Listed {
  char32_t code_point = 0;
  std::vector<int> typical_ids;
};

int run_characters(const CharactersCommand& command) {
  const int typical = command.typical.empty() ? 0 : typical_id_from(command.typical);  // 0: any
  std::u32string text;
  if (!command.text.empty()) text = characters_from(command.text, "--text");
  FilePlan files;
  add_library_inputs(files, command.library);
  const CharacterSource source(command.library);

  // The candidates: the text's characters in order, each once (those the library lacks are named), or
  // every character of the library.
  std::vector<char32_t> candidates;
  std::vector<char32_t> not_found;
  if (!command.text.empty()) {
    std::set<char32_t> seen;
    for (char32_t c : text) {
      if (is_white_space(c) || !seen.insert(c).second) continue;
      (source.contains(c) ? candidates : not_found).push_back(c);
    }
  } else {
    candidates = source.characters();
  }
  std::vector<Listed> listed;
  for (char32_t c : candidates) {
    Listed entry{c, {}};
    for (const Stroke& stroke : source.load(c).strokes) entry.typical_ids.push_back(stroke.typical_id);
    if (command.strokes != 0 && entry.typical_ids.size() != static_cast<std::size_t>(command.strokes))
      continue;
    if (typical != 0 &&
        std::find(entry.typical_ids.begin(), entry.typical_ids.end(), typical) == entry.typical_ids.end())
      continue;
    listed.push_back(std::move(entry));
  }

  if (command.json) {
    nlohmann::json characters = nlohmann::json::array();
    for (const Listed& entry : listed) {
      nlohmann::json acronyms = nlohmann::json::array();
      for (int id : entry.typical_ids) acronyms.push_back(std::string(typical_stroke(id).acronym));
      characters.push_back({{"character", encode_utf8(entry.code_point)},
                            {"code_point", code_point_text(entry.code_point)},
                            {"strokes", entry.typical_ids.size()},
                            {"typical_ids", entry.typical_ids},
                            {"typical_strokes", acronyms}});
    }
    nlohmann::json missing = nlohmann::json::array();
    for (char32_t c : not_found) missing.push_back(encode_utf8(c));
    const nlohmann::json out = {{"library", source.description()},
                                {"count", listed.size()},
                                {"characters", characters},
                                {"not_found", missing}};
    write_standard_output(json_text(out, 2) + "\n");
    return 0;
  }
  std::string table = "char  code point  strokes  typical strokes\n";
  for (const Listed& entry : listed) {
    std::string acronyms;
    for (int id : entry.typical_ids)
      acronyms += (acronyms.empty() ? "" : " ") + std::string(typical_stroke(id).acronym);
    char line[64];
    std::snprintf(line, sizeof line, "  %-10s  %7zu  ", code_point_text(entry.code_point).c_str(),
                  entry.typical_ids.size());
    table += encode_utf8(entry.code_point) + "  " + line + acronyms + "\n";
  }
  table += std::to_string(listed.size()) + (listed.size() == 1 ? " character" : " characters") +
           "; library: " + source.description() + "\n";
  if (!not_found.empty()) {
    std::string missing;
    // Each with its code point, as printable text: the text is the user's, and a control character (an
    // escape sequence), a combining mark or a variation selector would otherwise act on the terminal or
    // vanish into its neighbour.
    for (char32_t c : not_found) {
      if (!missing.empty()) missing += ", ";
      missing.append(printable_one_line(encode_utf8(c))).append(" (").append(code_point_text(c)).append(")");
    }
    table.append("not in the library: ").append(printable_one_line(missing, missing.size())).append("\n");
  }
  write_standard_output(table);
  return 0;
}

}  // namespace

void add_characters_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<CharactersCommand>();
  CLI::App* app = commands.add(
      root, "characters",
      "List the characters there are: all, or by stroke count, by a typical stroke, or those of a text",
      [command] { return run_characters(*command); });
  add_integer(*app, "--strokes", command->strokes, "N", "only characters with N strokes", 1, 255, "any");
  add_text(*app, "--typical", command->typical, "STROKE",
           "only characters with this typical stroke: its ID (1-39), acronym (HZG), name (横折钩) or stroke "
           "character (calligraphy strokes lists them)",
           "any");
  add_text(*app, "--text", command->text, "TEXT",
           "only the characters of this text (UTF-8), in its order, each once; those not in the library are "
           "named",
           "every character of the library");
  add_flag(*app, "--json", command->json, "print the list as JSON");
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
