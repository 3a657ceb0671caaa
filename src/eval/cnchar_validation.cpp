#include "eval/cnchar_validation.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <ostream>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/core/worker_threads.hpp"
#include "calligraphy/model/typical_strokes.hpp"

namespace calligraphy::cli {
namespace {

// cnchar letter per typical ID (index ID - 1). From cnchar's stroke table (theajack/cnchar):
// cnchar merges 横撇/横钩 (e), 横折折/横折弯 (v), 横折折折钩/横撇弯钩 (w), 横斜钩/横折弯钩 (o),
// 竖弯/竖折 (b), 竖折撇/竖折折 (x), 斜钩/卧钩 (y), and writes 竖撇 as 撇 (s). It has no letter for
// the variants 长点, 平撇, 提捺, 撇钩 and 竖弯左; they map to the flat stroke they vary.
constexpr std::array<char, 39> kLetters = {
    'j',  // 1 H 横
    'f',  // 2 S 竖
    's',  // 3 P 撇
    'k',  // 4 D 点
    'l',  // 5 N 捺
    'i',  // 6 T 提
    'c',  // 7 HZ 横折
    'e',  // 8 HP 横撇
    'e',  // 9 HG 横钩
    'r',  // 10 HZG 横折钩
    'p',  // 11 HZT 横折提
    'v',  // 12 HZW 横折弯
    'v',  // 13 HZZ 横折折
    'o',  // 14 HXG 横斜钩
    'o',  // 15 HZWG 横折弯钩
    'w',  // 16 HPWG 横撇弯钩
    'a',  // 17 HZZP 横折折撇
    'w',  // 18 HZZZG 横折折折钩
    'q',  // 19 HZZZ 横折折折
    'h',  // 20 ST 竖提
    'b',  // 21 SZ 竖折
    'g',  // 22 SG 竖钩
    'b',  // 23 SW 竖弯
    'u',  // 24 SWG 竖弯钩
    'x',  // 25 SZP 竖折撇
    'x',  // 26 SZZ 竖折折
    'z',  // 27 SZWG 竖折折钩
    'm',  // 28 PD 撇点
    'n',  // 29 PZ 撇折
    'y',  // 30 XG 斜钩
    't',  // 31 WG 弯钩
    's',  // 32 SP 竖撇
    'd',  // 33 D2 左点
    'k',  // 34 CD 长点
    'y',  // 35 BXG 卧钩
    's',  // 36 PP 平撇
    'l',  // 37 TN 提捺
    's',  // 38 PG 撇钩
    's',  // 39 SWZ 竖弯左
};

struct LetterName {
  char letter;
  std::string_view name;
};
// cnchar-order 3.2.6's own stroke table (names as the package writes them).
constexpr LetterName kLetterNames[] = {
    {'j', "横"},       {'f', "竖"},        {'s', "撇"},
    {'k', "点"},       {'l', "捺"},        {'i', "提"},
    {'d', "点2"},      {'c', "横折"},      {'e', "横撇|横钩"},
    {'r', "横折钩"},   {'p', "横折提"},    {'v', "横折折|横折弯"},
    {'q', "横折折折"}, {'a', "横折折撇"},  {'w', "横折折折钩|横撇弯钩"},
    {'o', "横斜钩"},   {'h', "竖提"},      {'g', "竖钩"},
    {'b', "竖弯"},     {'u', "竖弯钩"},    {'x', "竖折撇|竖折折"},
    {'z', "竖折折钩"}, {'n', "撇折"},      {'m', "撇点"},
    {'t', "弯钩"},     {'y', "斜钩|卧钩"},
};

// How classify_pieces decides (docs/classification.md, section 2).
constexpr const char* kMethod = R"(## How strokes are classified

`classify_pieces` (src/model/fitting.cpp) takes the corner-to-corner pieces of a fitted stroke (start
and end directions on the piece's interior, length, turn of its last fifth). It ignores a short
down-right first piece (the brush's entry), then picks the least cost over the 39 templates of
docs/typical-strokes.md and a few observed forms of them (a corner rounded into a bend, a hook the
median lacks, a 横折 ending with a brush tick): squared direction errors in units of the templates'
tolerances plus soft penalties for piece counts, hook fractions and lengths. Four rules settle
single-piece strokes whose directions overlap, each measured over this corpus: a short stroke falling
slightly left is a 左点 when its end curls back toward the vertical, else a 竖 when it ends steeper
than -112 degrees; a short stroke falling steeply right is a 点 when its end turns clockwise, else a
竖; a 横 ends with a press (its end turns down), a 提 flicks up straight; a long flat stroke whose end
turns up is the flat 捺. The templates and rules were tuned on the whole corpus; the tests assert the
agreement on a fixed sample of 121 characters (tests/data/hanzi-writer-sample). The figures after each
change are in docs/classification-log.md.

)";

std::string percent(std::size_t part, std::size_t whole) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%",
                whole ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0);
  return text;
}

std::string acronym(int id) { return std::string(typical_stroke(id).acronym); }

}  // namespace

char cnchar_letter(int typical_id) {
  (void)typical_stroke(typical_id);  // range check
  return kLetters[static_cast<std::size_t>(typical_id - 1)];
}

std::string_view cnchar_letter_name(char letter) {
  for (const auto& l : kLetterNames) {
    if (l.letter == letter) return l.name;
  }
  return "?";
}

std::map<char32_t, std::string> parse_cnchar_orders(std::string_view text, const std::string& source) {
  // Pairs "X":"letters" with X one UTF-8 character and letters in a-z (the map in cnchar.order.min.js;
  // spaces around the colon are allowed, so a JSON object of the same pairs reads too).
  std::map<char32_t, std::string> orders;
  const auto skip_spaces = [&text](std::size_t k) {
    while (k < text.size() && (text[k] == ' ' || text[k] == '\n' || text[k] == '\r' || text[k] == '\t')) ++k;
    return k;
  };
  std::size_t i = 0;
  while ((i = text.find('"', i)) != std::string_view::npos) {
    const std::size_t start = i + 1;
    i = start;
    if (start >= text.size()) break;
    const auto lead = static_cast<unsigned char>(text[start]);
    const std::size_t width = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC0 ? 2 : 0;
    if (width == 0 || start + width >= text.size() || text[start + width] != '"') continue;
    std::size_t k = skip_spaces(start + width + 1);
    if (k >= text.size() || text[k] != ':') continue;
    k = skip_spaces(k + 1);
    if (k >= text.size() || text[k] != '"') continue;
    std::size_t end = k + 1;
    while (end < text.size() && text[end] >= 'a' && text[end] <= 'z') ++end;
    if (end == k + 1 || end >= text.size() || text[end] != '"') continue;
    try {
      const std::u32string cp = decode_utf8(text.substr(start, width));
      if (cp.size() == 1) orders[cp[0]] = std::string(text.substr(k + 1, end - k - 1));
    } catch (const InvalidArgument&) {
      continue;  // not a character key
    }
    i = end + 1;
  }
  if (orders.empty())
    throw DataError(source + ": no \"char\":\"letters\" stroke map found (is it cnchar.order.min.js?)");
  return orders;
}

CncharValidation validate_against_cnchar(const CharacterLibrary& library,
                                         const std::map<char32_t, std::string>& labels,
                                         const FitOptions& options, unsigned threads,
                                         std::ostream* features) {
  struct Outcome {
    enum { missing, count_mismatch, compared } status = missing;
    std::vector<int> ids;
    std::vector<std::vector<StrokePiece>> pieces;
  };
  const std::vector<std::pair<char32_t, std::string>> items(labels.begin(), labels.end());
  std::vector<Outcome> outcomes(items.size());
  // A character whose data cannot be read ends the validation with that error (the first in order).
  for_each_item(items.size(), std::max(1u, threads), [&](std::size_t k) {
    const auto& [cp, letters] = items[k];
    if (!library.contains(cp)) return;
    const CharacterData data = library.load_data(cp);
    if (data.medians.size() != letters.size()) {
      outcomes[k].status = Outcome::count_mismatch;
      return;
    }
    outcomes[k].status = Outcome::compared;
    for (const auto& median : data.medians) {
      const FittedStroke f = fit_stroke(median, options);
      outcomes[k].ids.push_back(f.stroke.typical_id);
      outcomes[k].pieces.push_back(f.pieces);
    }
  });

  CncharValidation result;
  result.labelled = items.size();
  for (std::size_t k = 0; k < items.size(); ++k) {
    const auto& [cp, letters] = items[k];
    const Outcome& o = outcomes[k];
    if (o.status == Outcome::missing) {
      ++result.missing;
      continue;
    }
    if (o.status == Outcome::count_mismatch) {
      result.count_mismatch.push_back(cp);
      continue;
    }
    ++result.compared;
    bool all = true;
    for (std::size_t s = 0; s < o.ids.size(); ++s) {
      ++result.strokes;
      ++result.confusion[letters[s]][o.ids[s]];
      if (features) {
        *features << encode_utf8(cp) << ' ' << s << ' ' << letters[s] << ' ' << o.ids[s];
        for (const auto& p : o.pieces[s])
          *features << ' ' << p.start_direction_deg << ' ' << p.end_direction_deg << ' ' << p.length << ' '
                    << p.exit_turn_deg;
        *features << '\n';
      }
      if (cnchar_letter(o.ids[s]) == letters[s]) {
        ++result.agreeing;
      } else {
        all = false;
        result.mismatches.push_back({cp, s, letters[s], o.ids[s]});
      }
    }
    if (all) ++result.characters_all_agree;
  }
  return result;
}

namespace {

// Letters in cnchar's order of frequency in the compared strokes, then alphabetically.
std::vector<char> letters_by_frequency(const CncharValidation& r) {
  std::vector<std::pair<std::size_t, char>> counts;
  for (const auto& [letter, row] : r.confusion) {
    std::size_t n = 0;
    for (const auto& [id, c] : row) n += c;
    counts.emplace_back(n, letter);
  }
  std::sort(counts.begin(), counts.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::vector<char> letters;
  for (const auto& c : counts) letters.push_back(c.second);
  return letters;
}

struct Confusion {
  char expected;
  int id;
  std::size_t count;
  std::vector<std::pair<char32_t, std::size_t>> examples;
};

std::vector<Confusion> frequent_confusions(const CncharValidation& r, std::size_t examples) {
  std::map<std::pair<char, int>, Confusion> by_pair;
  for (const auto& m : r.mismatches) {
    auto& c = by_pair[{m.expected, m.typical_id}];
    c.expected = m.expected;
    c.id = m.typical_id;
    ++c.count;
    if (c.examples.size() < examples) c.examples.emplace_back(m.character, m.stroke);
  }
  std::vector<Confusion> list;
  for (auto& [key, c] : by_pair) list.push_back(std::move(c));
  std::stable_sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.count > b.count; });
  return list;
}

}  // namespace

std::string cnchar_validation_markdown(const CncharValidation& r, const std::string& data_description,
                                       const std::string& labels_description) {
  std::string md;
  const auto line = [&md](const std::string& s) { md += s + "\n"; };
  line("# Typical-stroke classification against cnchar");
  line("");
  line("<!-- Generated by `calligraphy corpus validate --markdown docs/classification.md`; do not edit. -->");
  line("");
  line(
      "Each stroke of a character is fitted (default `FitOptions`) and classified into one of the 39 "
      "typical");
  line("strokes (`docs/typical-strokes.md`). The ID is mapped to the letter of npm `cnchar-order` 3.2.6");
  line("(MIT), which labels every stroke of 6,939 characters with one of 26 coarser letters, and compared");
  line("with cnchar's letter for that stroke. Only characters that both sources cover with equal stroke");
  line("counts are compared. Reproduce with:");
  line("");
  line("```");
  line("scripts/fetch-hanzi-writer-data.sh   # prints DIR");
  line("scripts/fetch-cnchar-order.sh        # prints FILE (cnchar.order.min.js)");
  line("calligraphy corpus validate --data DIR --cnchar FILE --markdown docs/classification.md");
  line("```");
  line("");
  md += kMethod;
  line("## Figures");
  line("");
  line("| | |");
  line("|---|---:|");
  line("| Data | " + data_description + " |");
  line("| Labels | " + labels_description + " |");
  line("| Characters labelled by cnchar | " + std::to_string(r.labelled) + " |");
  line("| not in the data (skipped) | " + std::to_string(r.missing) + " |");
  line("| different stroke counts (skipped) | " + std::to_string(r.count_mismatch.size()) + " |");
  line("| **Characters compared** | **" + std::to_string(r.compared) + "** |");
  line("| Strokes compared | " + std::to_string(r.strokes) + " |");
  line("| **Per-stroke agreement** | **" + percent(r.agreeing, r.strokes) + "** (" +
       std::to_string(r.agreeing) + ") |");
  line("| Characters with every stroke agreeing | " + percent(r.characters_all_agree, r.compared) + " (" +
       std::to_string(r.characters_all_agree) + ") |");
  if (!r.count_mismatch.empty()) {
    std::string list;
    for (char32_t cp : r.count_mismatch) list += encode_utf8(cp);
    line("");
    line("Skipped for different stroke counts: " + list + ".");
  }
  line("");
  line("## Mapping of typical-stroke IDs to cnchar letters");
  line("");
  line("| ID | Acronym | Name | cnchar letter | cnchar name |");
  line("|---:|---|---|---|---|");
  for (const TypicalStroke& t : typical_strokes()) {
    const char letter = cnchar_letter(t.id);
    line("| " + std::to_string(t.id) + " | " + std::string(t.acronym) + " | " + std::string(t.name_zh) +
         " | `" + std::string(1, letter) + "` | " + std::string(cnchar_letter_name(letter)) + " |");
  }
  line("");
  line("## Agreement by cnchar letter");
  line("");
  line("Rows are cnchar's letters (most frequent first); the columns give how our typical IDs classified");
  line("those strokes (the IDs that agree are in bold; at most 6 IDs per row, the rest summed as 'other').");
  line("");
  line("| Letter | cnchar name | Strokes | Agreement | Classified as |");
  line("|---|---|---:|---:|---|");
  for (char letter : letters_by_frequency(r)) {
    const auto& row = r.confusion.at(letter);
    std::size_t n = 0;
    std::size_t ok = 0;
    std::vector<std::pair<std::size_t, int>> cells;
    for (const auto& [id, c] : row) {
      n += c;
      if (cnchar_letter(id) == letter) ok += c;
      cells.emplace_back(c, id);
    }
    std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    std::string text;
    std::size_t other = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
      if (k >= 6) {
        other += cells[k].first;
        continue;
      }
      const bool agrees = cnchar_letter(cells[k].second) == letter;
      const std::string name = acronym(cells[k].second) + " " + std::to_string(cells[k].first);
      if (k) text += ", ";
      text += agrees ? "**" + name + "**" : name;
    }
    if (other) text += ", other " + std::to_string(other);
    line("| `" + std::string(1, letter) + "` | " + std::string(cnchar_letter_name(letter)) + " | " +
         std::to_string(n) + " | " + percent(ok, n) + " | " + text + " |");
  }
  line("");
  line("## Most frequent confusions");
  line("");
  line("Examples are character:stroke (1-based).");
  line("");
  line("| cnchar letter | classified as | strokes | examples |");
  line("|---|---|---:|---|");
  const auto confusions = frequent_confusions(r, 8);
  for (std::size_t k = 0; k < confusions.size() && k < 25; ++k) {
    const auto& c = confusions[k];
    std::string examples;
    for (const auto& [cp, s] : c.examples) {
      if (!examples.empty()) examples += ' ';
      examples += encode_utf8(cp);
      examples += ':';
      examples += std::to_string(s + 1);
    }
    line("| `" + std::string(1, c.expected) + "` " + std::string(cnchar_letter_name(c.expected)) + " | " +
         acronym(c.id) + " (`" + std::string(1, cnchar_letter(c.id)) + "`) | " + std::to_string(c.count) +
         " | " + examples + " |");
  }
  return md;
}

nlohmann::json cnchar_validation_json(const CncharValidation& r) {
  nlohmann::json confusion = nlohmann::json::object();
  for (const auto& [letter, row] : r.confusion) {
    nlohmann::json cells = nlohmann::json::object();
    for (const auto& [id, c] : row) cells[acronym(id)] = c;
    confusion[std::string(1, letter)] = cells;
  }
  nlohmann::json skipped = nlohmann::json::array();
  for (char32_t cp : r.count_mismatch) skipped.push_back(encode_utf8(cp));
  nlohmann::json mapping = nlohmann::json::object();
  for (const TypicalStroke& t : typical_strokes())
    mapping[std::to_string(t.id)] = std::string(1, cnchar_letter(t.id));
  nlohmann::json top = nlohmann::json::array();
  for (const auto& c : frequent_confusions(r, 8)) {
    nlohmann::json examples = nlohmann::json::array();
    for (const auto& [cp, s] : c.examples)
      examples.push_back({{"character", encode_utf8(cp)}, {"stroke", s + 1}});
    top.push_back({{"cnchar", std::string(1, c.expected)},
                   {"classified_as", acronym(c.id)},
                   {"strokes", c.count},
                   {"examples", examples}});
  }
  return {{"labelled", r.labelled},
          {"missing_from_data", r.missing},
          {"stroke_count_mismatch", skipped},
          {"characters_compared", r.compared},
          {"strokes_compared", r.strokes},
          {"strokes_agreeing", r.agreeing},
          {"agreement", r.agreement()},
          {"characters_all_agree", r.characters_all_agree},
          {"mapping", mapping},
          {"confusion", confusion},
          {"confusions", top}};
}

}  // namespace calligraphy::cli
