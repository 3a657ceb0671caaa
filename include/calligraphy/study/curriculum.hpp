#pragma once
/// \file curriculum.hpp
/// What a learner should practise next, from its record: characters that bring typical strokes (paper
/// section 3.1) it has not written yet, and typical strokes it writes worst again, spaced over new
/// characters rather than the same one (spaced repetition; Cepeda et al. 2006, Psychol Bull 132:354).
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/study/study_tables.hpp"

namespace calligraphy {

/// A learner's record of one typical stroke.
struct TypicalStrokeRecord {
  int typical_id = 0;
  std::size_t written = 0;                 ///< strokes of this type matched in the learner's saved trials
  std::optional<double> mean_deviation_m;  ///< their mean deviation [m]; nullopt when none was matched
};

/// The record of `subject` in `tables` (`read_study_tables`), by typical stroke ID: every stroke row of the
/// subject's saved trials, written or not. Throws InvalidArgument naming the subject when it has no row.
[[nodiscard]] std::vector<TypicalStrokeRecord> typical_stroke_record(const StudyTables& tables,
                                                                     const std::string& subject);

/// The most characters one proposal of `calligraphy curriculum --count` or Python's propose_characters holds.
inline constexpr std::size_t kMaxProposedCharacters = 1000;

/// One character proposed, and why.
struct ProposedCharacter {
  char32_t character = 0;
  std::vector<int> new_strokes;   ///< typical strokes it brings that the learner never wrote
  std::vector<int> weak_strokes;  ///< typical strokes it repeats that the learner writes worst
};

/// Up to `count` characters of `candidates` to practise next, greedily: each time the candidate that adds
/// most (2 per typical stroke never written, 1 per weak one: written, with a mean deviation above the median
/// of the learner's typical strokes) to what the characters chosen so far cover, ties to fewer strokes, then
/// to the earlier candidate; candidates that add nothing are not proposed. A candidate the learner has
/// written is not proposed. `typical_ids` gives a candidate's typical strokes, one per stroke. Throws what
/// `typical_ids` throws. A `count` of 0 or no candidates propose nothing; the command and the Python module
/// refuse both (count in 1..kMaxProposedCharacters).
[[nodiscard]] std::vector<ProposedCharacter> propose_characters(
    const std::vector<TypicalStrokeRecord>& record, const std::u32string& written_characters,
    const std::u32string& candidates, std::size_t count,
    const std::function<std::vector<int>(char32_t)>& typical_ids);

/// The characters `subject` has written in `tables` (each once, in order of first writing).
[[nodiscard]] std::u32string written_characters(const StudyTables& tables, const std::string& subject);

}  // namespace calligraphy
