#pragma once
// Validation of the typical-stroke classification against the per-stroke letters of npm
// `cnchar-order` 3.2.6 (MIT, theajack/cnchar; letter meanings in its stroke table). cnchar's
// letters are coarser than the 39 typical strokes (e.g. `e` is both 横撇 HP and 横钩 HG), so each ID
// maps to one letter and agreement is counted at the letter's granularity.
#include <iosfwd>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::cli {

/// cnchar's letter for a typical-stroke ID (1-39). Throws InvalidArgument outside 1-39.
char cnchar_letter(int typical_id);
/// cnchar's own name for a letter (from the package's stroke table), e.g. 'e' -> "横撇|横钩".
std::string_view cnchar_letter_name(char letter);

/// The `"char":"letters"` map from cnchar.order.min.js (or any text holding such pairs). Throws
/// DataError naming `source` when the text holds none.
std::map<char32_t, std::string> parse_cnchar_orders(std::string_view text, const std::string& source);

/// One disagreeing stroke: character, 0-based stroke index, cnchar's letter, our typical ID.
struct StrokeMismatch {
  char32_t character = 0;
  std::size_t stroke = 0;
  char expected = 0;
  int typical_id = 0;
};

/// Result of comparing the fitted model of each character with cnchar's letters.
struct CncharValidation {
  std::size_t labelled = 0;              ///< characters in the cnchar map
  std::size_t compared = 0;              ///< characters compared (in both, equal stroke counts)
  std::size_t missing = 0;               ///< in cnchar, not in the data
  std::vector<char32_t> count_mismatch;  ///< in both, different stroke counts (skipped)
  std::size_t strokes = 0;               ///< strokes compared
  std::size_t agreeing = 0;              ///< strokes whose ID maps to cnchar's letter
  std::size_t characters_all_agree = 0;
  /// confusion[cnchar letter][typical ID] = strokes.
  std::map<char, std::map<int, std::size_t>> confusion;
  std::vector<StrokeMismatch> mismatches;  ///< every disagreeing stroke, in code-point order

  [[nodiscard]] double agreement() const {
    return strokes ? static_cast<double>(agreeing) / static_cast<double>(strokes) : 0.0;
  }
};

/// Fits every character of `labels` found in `library` (with `options`) on `threads` threads and
/// compares stroke by stroke. Deterministic: the result does not depend on `threads`. When `features` is
/// given, writes one line per compared stroke: character, stroke index, cnchar letter, typical ID, then
/// start direction, end direction, length and exit turn of each piece (for studying the classifier).
CncharValidation validate_against_cnchar(const CharacterLibrary& library,
                                         const std::map<char32_t, std::string>& labels,
                                         const FitOptions& options, unsigned threads,
                                         std::ostream* features = nullptr);

/// Markdown report (docs/classification.md): figures, mapping, confusion table, frequent confusions.
std::string cnchar_validation_markdown(const CncharValidation& result, const std::string& data_description,
                                       const std::string& labels_description);
/// The same as JSON.
nlohmann::json cnchar_validation_json(const CncharValidation& result);

}  // namespace calligraphy::cli
