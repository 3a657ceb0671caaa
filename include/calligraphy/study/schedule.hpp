#pragma once
/// \file schedule.hpp
/// The trials of one subject's session, in order, as a protocol prescribes them: the practice block,
/// then one block per tested condition (two per condition for `abba`), each block a number of rounds
/// through the test characters. Deterministic: the same protocol, subject id and number give the same
/// schedule, so an interrupted session resumes on the same plan.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/study/protocol.hpp"

namespace calligraphy {

enum class StudyPhase { practice, test };
/// "practice" or "test".
[[nodiscard]] const char* to_string(StudyPhase phase) noexcept;

/// One trial of a session.
struct PlannedTrial {
  std::size_t index = 0;  ///< 0-based position in the session
  StudyPhase phase = StudyPhase::test;
  std::size_t block = 0;  ///< 0-based; the practice block, when there is one, is block 0
  std::string condition;  ///< a condition of the protocol
  std::u32string characters;
  std::size_t item = 0;         ///< index of `characters` in its phase's list (the paper's C1 is 0)
  int repetition = 1;           ///< 1-based: the how-many-th time this item is written in this condition
  double break_before_s = 0.0;  ///< rest before this trial [s]
};

/// Who is planned for: the id names the session folder and seeds random orders; the number (1-based)
/// picks the row of a Latin square or the direction of an ABBA sequence.
struct SubjectAssignment {
  std::string id;          ///< [A-Za-z0-9_-], 1..64 characters
  std::size_t number = 0;  ///< 1-based; 0: unknown (allowed unless the order needs it)
};

/// The conditions of the test blocks in order for `subject`. `latin_square`: row (number - 1) mod rows of a
/// balanced Latin square (Williams 1949, Aust. J. Sci. Res. A 2:149-168: every condition follows every
/// other equally often; n rows for an even number n of conditions, 2n for odd n). `abba`: the listed order
/// then its reverse for odd numbers, the reversed order then the listed one for even numbers. `random`: a
/// Fisher-Yates shuffle seeded from the protocol's seed and the subject id. Throws InvalidArgument naming
/// the subject when the id is not a label, or when the order needs a number and it is 0.
[[nodiscard]] std::vector<std::string> test_block_conditions(const StudyProtocol& protocol,
                                                             const SubjectAssignment& subject);

/// Every trial of the session (see the file comment). Breaks: `between_blocks_s` before the first trial of
/// each block after the first, `duration_s` after every `every_trials` trials (the longer one when both
/// fall on one trial). Throws as `test_block_conditions`.
[[nodiscard]] std::vector<PlannedTrial> plan_session(const StudyProtocol& protocol,
                                                     const SubjectAssignment& subject);

/// The number at the end of a subject id ("S07" -> 7), or 0 when it does not end in digits.
[[nodiscard]] std::size_t trailing_number(std::string_view subject_id) noexcept;

}  // namespace calligraphy
