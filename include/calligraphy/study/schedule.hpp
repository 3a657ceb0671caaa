#pragma once
/// \file schedule.hpp
/// The trials of one subject's session, in order, as a protocol prescribes them: its phases, each a block
/// per condition, each block a number of rounds through the phase's characters. Deterministic: the same
/// protocol, subject id and number give the same schedule, so an interrupted session resumes on the same
/// plan.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/study/protocol.hpp"

namespace calligraphy {

/// One trial of a session.
struct PlannedTrial {
  std::size_t index = 0;  ///< 0-based position in the session
  StudyPhase phase = StudyPhase::test;
  std::size_t block = 0;  ///< 0-based; the practice block, when there is one, is block 0
  std::string condition;  ///< a condition of the protocol
  std::u32string characters;
  std::size_t item = 0;  ///< index of `characters` in its phase's list (the paper's C1 is 0)
  int repetition = 1;    ///< 1-based: the how-many-th time this item is written in this phase and condition
  double break_before_s = 0.0;  ///< rest before this trial [s]
};

/// Who is planned for: the id names the session folder and seeds random orders; the number (1-based)
/// picks the row of a Latin square or the direction of an ABBA sequence.
struct SubjectAssignment {
  std::string id;          ///< [A-Za-z0-9_-], 1..64 characters
  std::size_t number = 0;  ///< 1-based; 0: unknown (allowed unless the order needs it)
};

/// The conditions of `phase`'s blocks in order for `subject`. A practice phase's as listed. Within subjects,
/// by the protocol's order:
/// `latin_square`: row (number - 1) mod rows of a balanced Latin square (Williams 1949, Aust. J. Sci. Res. A
/// 2:149-168: every condition follows every other equally often; n rows for an even number n of conditions,
/// 2n for odd n); `abba`: the listed order then its reverse for odd numbers, the reversed order then the
/// listed one for even numbers; `random`: a Fisher-Yates shuffle seeded from the protocol's seed and the
/// subject id. Between subjects, the one condition of the subject's group: the (number - 1) mod n-th listed
/// (groups balanced in turn), or under a `random` order a seeded draw. Throws InvalidArgument naming the
/// subject when the id is not a label, or when the order or the groups need a number and it is 0.
[[nodiscard]] std::vector<std::string> block_conditions(const StudyProtocol& protocol,
                                                        const ProtocolPhase& phase,
                                                        const SubjectAssignment& subject);

/// The subject's group: the conditions `block_conditions` gives it in the protocol's between-subjects
/// phases, joined by "/" in phase order; "" when every phase is within subjects. Throws as
/// `block_conditions`.
[[nodiscard]] std::string subject_group(const StudyProtocol& protocol, const SubjectAssignment& subject);

/// Every trial of session `session` (1-based, up to `protocol.session_count()`): its phases in order, each
/// phase a block per condition of `block_conditions` (two per condition for `abba`, practice excepted), each
/// block a number of rounds through the phase's characters. Rests: `between_blocks_s` before the first
/// trial of each block after the first, a phase's `delay_s` before its first trial when it is not the
/// session's first phase, `duration_s` after every `every_trials` trials (the longest when several fall on
/// one trial). Throws InvalidArgument for a session the protocol does not have, a transfer choice not
/// resolved (`resolve_transfer_choices`), and as `block_conditions`.
[[nodiscard]] std::vector<PlannedTrial> plan_session(const StudyProtocol& protocol,
                                                     const SubjectAssignment& subject, int session = 1);

/// The number at the end of a subject id ("S07" -> 7), or 0 when it does not end in digits.
[[nodiscard]] std::size_t trailing_number(std::string_view subject_id) noexcept;

}  // namespace calligraphy
