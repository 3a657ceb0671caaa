#pragma once
/// \file schedule.hpp
/// The trials of one subject's session, in order, as a protocol prescribes them: its phases, each a block
/// per condition, each block a number of rounds through the phase's characters. Deterministic: the same
/// protocol, subject id and number give the same schedule, so an interrupted session resumes on the same
/// plan.
#include <cstddef>
#include <map>
#include <span>
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
  /// The item's set (ProtocolPhase::item_sets); "" when the phase lists characters of no set.
  std::string item_set;
  /// The subject's crossover sequence (CrossoverAssignment::sequence: "AB", "BA", "ACB", ...), the same on
  /// every trial of the subject; "" when the protocol has no crossover phase.
  std::string sequence;
  /// The 1-based crossover period in which the item's set is trained (a transfer set: its source set's);
  /// 0 when the set is not trained in the crossover phase.
  int period = 0;
  /// The condition the item is or was trained under in the crossover phase, on every phase's trial (a
  /// pre-test's too); a transfer set's: its source set's; "" when none.
  std::string trained_condition;
};

/// Who is planned for: the id names the session folder and seeds random orders; the number (1-based)
/// picks the row of a Latin square or the direction of an ABBA sequence.
struct SubjectAssignment {
  std::string id;          ///< [A-Za-z0-9_-], 1..64 characters
  std::size_t number = 0;  ///< 1-based; 0: unknown (allowed unless the order needs it)
};

/// The conditions of `phase`'s blocks in order for `subject`. A practice phase's as listed (between subjects:
/// the group's one condition, as below). Within subjects,
/// by the protocol's order:
/// `latin_square`: row (number - 1) mod rows of a balanced Latin square (Williams 1949, Aust. J. Sci. Res. A
/// 2:149-168: every condition follows every other equally often; n rows for an even number n of conditions,
/// 2n for odd n); `abba`: the listed order then its reverse for odd numbers, the reversed order then the
/// listed one for even numbers; `random`: a Fisher-Yates shuffle seeded from the protocol's seed and the
/// subject id. Beside between-subjects phases (groups in turn by number), the row and the direction come from
/// the subject's cell m = j + g instead of number - 1 (g = (number - 1) mod G its group, j = (number - 1) / G
/// its place in the group, G as `crossover_assignment`), so that every group gets every row and both
/// directions and the order is not the group. Between subjects, the one condition of the subject's group: the
/// (number - 1) mod n-th listed (groups balanced in turn), or under a `random` order a seeded draw. A
/// crossover phase: its conditions in the subject's period order (`crossover_assignment`), whatever the
/// protocol's order. Throws InvalidArgument naming the subject when the id is not a label, or when the order
/// or the groups need a number and it is 0.
[[nodiscard]] std::vector<std::string> block_conditions(const StudyProtocol& protocol,
                                                        const ProtocolPhase& phase,
                                                        const SubjectAssignment& subject);

/// How a crossover phase trains one of its item sets for a subject.
struct SetTraining {
  std::string condition;  ///< the condition the set is trained under
  int period = 0;         ///< 1-based: the block of the crossover phase in which it is trained
};

/// A subject's crossover (`crossover_assignment`).
struct CrossoverAssignment {
  /// The conditions in period order as letters of the crossover phase's listed conditions (A the first):
  /// "AB", "BA", "ACB", ...; "" when the protocol has no crossover phase.
  std::string sequence;
  std::size_t rotation = 0;             ///< q: listed condition i is trained on listed set (i + q) mod k
  std::vector<std::string> conditions;  ///< the condition of each period, in period order
  std::vector<std::string> sets;        ///< the set trained in each period, in period order
  /// By name: every set the crossover trains, and every `transfer_of` set of one (its source's training).
  std::map<std::string, SetTraining> trained;
};

/// The subject's sequence and set of each condition in the protocol's crossover phase (k listed conditions
/// and sets): row r = (number - 1) mod rows of the balanced Latin square `latin_square` uses (Williams 1949;
/// rows = k for even k, 2k for odd k) orders the conditions, and the rotation q = ((number - 1) / rows) mod k
/// pairs listed condition i with listed set (i + q) mod k. Period p trains condition listed[row[p - 1]] on
/// its set. Two conditions give subjects 1, 2, 3, 4: AB and BA with rotation 0, then AB and BA with rotation
/// 1, and again: sequence, period and set are balanced every rows x k subjects (4 for two conditions, 18 for
/// three, 16 for four). In a mixed design (between-subjects phases beside the crossover, their groups in turn
/// by number) the row and rotation come from the cell m = j + g instead of number - 1: g = (number - 1) mod G
/// the subject's group and j = (number - 1) / G its place in the group, G the least common multiple of those
/// phases' condition counts (1 under a random order). So every group gets every sequence and rotation over
/// its first rows x k subjects, and consecutive subjects consecutive cells (balanced over all subjects even
/// when G is larger than any study). An empty assignment when the protocol has no crossover phase. Throws
/// InvalidArgument naming the subject when its id is not a label or, with a crossover phase, its number is 0.
[[nodiscard]] CrossoverAssignment crossover_assignment(const StudyProtocol& protocol,
                                                       const SubjectAssignment& subject);

/// The crossover's pairing of conditions and sets in `assignment` (of `protocol`'s crossover phase): each
/// listed condition's letter and the set it trains, in listed order ("A:set1 B:set2"); "" without a
/// crossover phase.
[[nodiscard]] std::string set_pairing(const StudyProtocol& protocol, const CrossoverAssignment& assignment);

/// The subject's group: the conditions `block_conditions` gives it in the protocol's between-subjects
/// phases, joined by "/" in phase order; "" when every phase is within subjects. Throws as
/// `block_conditions`.
[[nodiscard]] std::string subject_group(const StudyProtocol& protocol, const SubjectAssignment& subject);

/// Every trial of session `session` (1-based, up to `protocol.session_count()`): its phases in order, each
/// phase a block per condition of `block_conditions` (two per condition for `abba`, practice excepted), each
/// block a number of rounds through the phase's characters (a crossover phase's block: through the items of
/// its period's set). Every trial names its item's set and the subject's crossover (`item_set`, `sequence`,
/// `period`, `trained_condition`). Rests: `between_blocks_s` before the first
/// trial of each block after the first, a phase's `delay_s` before its first trial when it is not the
/// session's first phase, `duration_s` after every `every_trials` trials (the longest when several fall on
/// one trial). Throws InvalidArgument for a session the protocol does not have, a transfer choice not
/// resolved (`resolve_transfer_choices`), and as `block_conditions`.
[[nodiscard]] std::vector<PlannedTrial> plan_session(const StudyProtocol& protocol,
                                                     const SubjectAssignment& subject, int session = 1);

/// Where one phase of a session is in its plan (`plan_session_phases`).
struct PlannedPhase {
  const ProtocolPhase* phase = nullptr;  ///< the protocol's phase (not owned: the protocol planned from)
  std::vector<std::string> blocks;       ///< the condition of each block, in order
  /// Parallel to `blocks`: the item set a crossover block trains (its period's); "" in any other phase.
  std::vector<std::string> block_sets;
  std::size_t first_trial = 0;  ///< index in `plan_session`'s trials of the phase's first trial
  std::size_t trials = 0;       ///< how many trials the phase plans
};

/// The phases of session `session` for `subject`, in order, each with its blocks and its trials' place in
/// `plan_session(protocol, subject, session)`, which plans them (the same call, so the two never differ).
/// Throws as `plan_session`.
[[nodiscard]] std::vector<PlannedPhase> plan_session_phases(const StudyProtocol& protocol,
                                                            const SubjectAssignment& subject,
                                                            int session = 1);

/// Subjects after which every assignment the protocol makes by subject number repeats (a full
/// counterbalancing square): the least common multiple of the between-subjects groups' cycle G (the lcm of
/// those phases' condition counts; 1 under a random order), the crossover's G x rows x k
/// (`crossover_assignment`), and, for within-subjects phases of two or more conditions, G x the Latin
/// square's rows (`latin_square`: n for even n, 2n for odd n) or G x 2 (`abba`): every group gets every order
/// (`block_conditions`). 1 when nothing is assigned by number.
[[nodiscard]] std::size_t counterbalancing_square(const StudyProtocol& protocol);

/// One factor a protocol counterbalances, and how many of some subjects are at each of its levels.
struct BalanceFactor {
  /// "group", "sequence", "set pairing" (each crossover letter's set: "A:set1 B:set2"), or "order of PHASE
  /// (POINTER)" (a within-subjects phase's block order under `latin_square`, `abba` or `random`)
  std::string name;
  /// Every level a full square gives, in order of subject number (under a random order: the drawn ones)
  std::vector<std::string> levels;
  std::vector<std::size_t> subjects;  ///< parallel to `levels`: subjects at each level (0 for some)
};

/// Most subjects a counterbalancing square may need and still be reached: the subjects `session run
/// --subjects` and `session plan` take (1,000), beyond any laboratory's recruitment. A protocol whose square
/// is larger (between-subjects phases of 23, 25 and 26 conditions repeat their groups every 14,950 subjects)
/// is balanced by no N a study can run: `Counterbalancing::warning` says so whatever N.
inline constexpr std::size_t kMaxReachableSquare = 1000;

/// How some subjects fill a protocol's counterbalancing (`counterbalancing`).
struct Counterbalancing {
  std::size_t square = 1;  ///< `counterbalancing_square`
  std::size_t groups = 1;  ///< G: subjects after which the between-subjects groups repeat (1: none, or drawn)
  std::size_t subjects = 0;  ///< subjects counted
  bool drawn = false;        ///< a random order: groups and orders drawn from each subject's id
  std::vector<BalanceFactor> factors;
  /// True when the subjects are a multiple of the square and every factor's levels hold as many subjects.
  [[nodiscard]] bool filled() const noexcept;
  /// False when the square needs more than kMaxReachableSquare subjects (and is not drawn).
  [[nodiscard]] bool reachable() const noexcept;
  /// "" when `filled()` (or no subject); else one sentence naming what is uneven, e.g. "N=5 does not fill the
  /// counterbalancing square of 4 subjects (recruit a multiple of 4): it leaves sequence BA with 2 subjects
  /// and AB with 3; set pairing A:set2 B:set1 with 2 subjects and A:set1 B:set2 with 3". A factor of more
  /// than six levels is counted, not listed ("group: 14,942 of its 14,950 levels with 0 subjects, 8 with
  /// 1"). A square beyond `reachable()` is said first: "a full counterbalancing square is 59,800 subjects
  /// (the between-subjects groups alone repeat every 14,950), more than any study can recruit (at most
  /// 1,000): no N balances this design; N=8 ...".
  [[nodiscard]] std::string warning() const;
};

/// Most subjects of a square whose levels `counterbalancing` lists (beyond it, the levels the subjects have).
inline constexpr std::size_t kMaxBalanceSquareShown = 100000;

/// How `subjects` fill the protocol's counterbalancing: each factor's levels from `subject_group`,
/// `crossover_assignment` and `block_conditions` (the assignment itself, not a model of it), and the
/// subjects at each. Throws as those functions (a subject id that is not a label, a number 0 where one is
/// needed).
[[nodiscard]] Counterbalancing counterbalancing(const StudyProtocol& protocol,
                                                std::span<const SubjectAssignment> subjects);

/// True for a valid subject id: 1..64 characters of [A-Za-z0-9_-] (it names the subject's folder).
[[nodiscard]] bool is_subject_id(std::string_view id);

/// The number at the end of a subject id ("S07" -> 7), or 0 when it does not end in digits.
[[nodiscard]] std::size_t trailing_number(std::string_view subject_id) noexcept;

}  // namespace calligraphy
