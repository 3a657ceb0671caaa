#pragma once
/// \file protocol.hpp
/// A study protocol: which characters are practised and tested, under which feedback conditions, how
/// often, in which order and with which breaks. Read from a JSON file (format: docs/experiments.md;
/// example: examples/protocols/paper-table5.json, the design of Wang, Zhang & Yao 2006, section 7).
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/render/guidance_schedule.hpp"
#include "calligraphy/trial/options.hpp"

namespace calligraphy {

/// What the writer gets in a condition.
enum class ConditionMode {
  vision,  ///< vision only: the paper force, no in-plane guidance (the paper's "no force feedback")
  haptic,  ///< vision and the guiding force of paper section 5 (the paper's "with force feedback")
  fading,  ///< guidance whose gain follows the writer's deviation over repetitions (GuidanceMode::fading)
  replay,  ///< guidance that replays a teacher's recorded trial of the item (GuidanceMode::replay)
  quiz,    ///< vision only, each stroke judged when the pen lifts (analysis/quiz.hpp)
  assist_as_needed,     ///< force only beyond a band that adapts to the writer's error
                        ///< (GuidanceMode::assist_as_needed)
  error_amplification,  ///< a bounded repulsive field (GuidanceMode::error_amplification)
  skill_adaptive,       ///< per repetition: fixed guidance or error amplification by the previous error
  timing,               ///< a minimum-jerk target along the stroke, no shape guidance (GuidanceMode::timing)
};

/// The modes' one spelling each, in a protocol's "mode", the records and the tables.
template <>
struct EnumTable<ConditionMode> {
  static constexpr std::string_view name = "ConditionMode";
  static constexpr std::array<EnumEntry<ConditionMode>, 9> entries{{
      {ConditionMode::vision, "vision", "vision only: the paper force, no in-plane guidance"},
      {ConditionMode::haptic, "haptic", "vision and the guiding force of the paper's section 5"},
      {ConditionMode::fading, "fading",
       "guidance whose gain follows the writer's deviation over repetitions"},
      {ConditionMode::replay, "replay", "guidance that replays a teacher's recorded trial of the item"},
      {ConditionMode::quiz, "quiz", "vision only, each stroke judged when the pen lifts"},
      {ConditionMode::assist_as_needed, "assist-as-needed",
       "force only beyond a band that adapts to the writer's error"},
      {ConditionMode::error_amplification, "error-amplification", "a bounded repulsive field"},
      {ConditionMode::skill_adaptive, "skill-adaptive",
       "per repetition: fixed guidance or error amplification by the previous error"},
      {ConditionMode::timing, "timing", "a minimum-jerk target along the stroke, no shape guidance"},
  }};
};

/// "vision", "haptic", "fading", "replay", "quiz", "assist-as-needed", "error-amplification",
/// "skill-adaptive", "timing" (EnumTable).
[[nodiscard]] const char* to_string(ConditionMode mode) noexcept;
/// Every mode, in declaration order.
[[nodiscard]] std::span<const ConditionMode> condition_modes() noexcept;
/// Whether trials of the mode render in-plane guidance (every mode but `vision` and `quiz`).
[[nodiscard]] bool renders_guidance(ConditionMode mode) noexcept;

/// A condition's in-plane guidance: the law its trials render, and what adapts it over the repetitions of
/// an item.
struct ConditionGuidance {
  /// The guidance law with the protocol's parameters (render/guidance_law.hpp). A fading law's gain and
  /// an assist-as-needed law's band are the first repetition's; a replay's teacher is added per trial.
  GuidanceLaw law = FixedGuidance{};
  /// What adapts over the repetitions of an item (render/guidance_schedule.hpp): the fading law's gain,
  /// the assist-as-needed law's band, or skill-adaptive's choice between `law` and the schedule's error
  /// amplification. Empty: every repetition renders `law` as it is.
  std::optional<GuidanceSchedule> schedule;
  /// Overrides the guidance stiffness K_et (ForceLawParameters, paper eq. 8) [N/m] when given.
  std::optional<double> stiffness_n_per_m;
};

/// One feedback condition: what the writer sees and is judged on (vision only, or the quiz), the guidance
/// (none, or a law with an optional schedule) and a replay's teachers. A protocol's "mode" is one
/// combination of these each (`condition_from_mode`, `condition_mode`):
///
/// | mode                | quiz | guidance law               | schedule         |
/// |---------------------|------|----------------------------|------------------|
/// | vision              | -    | -                          | -                |
/// | quiz                | yes  | -                          | -                |
/// | haptic              | -    | FixedGuidance              | -                |
/// | fading              | -    | FadingGuidance             | fading           |
/// | replay              | -    | ReplayGuidance             | -                |
/// | assist-as-needed    | -    | AssistAsNeededGuidance     | assist_as_needed |
/// | error-amplification | -    | ErrorAmplificationGuidance | -                |
/// | skill-adaptive      | -    | FixedGuidance              | skill_adaptive   |
/// | timing              | -    | TimingGuidance             | -                |
struct StudyCondition {
  std::string name;  ///< unique label, used in file names and reports: [A-Za-z0-9_-], 1..32 characters
  /// Each stroke judged when the pen lifts (analysis/quiz.hpp), with these options; empty: vision only.
  std::optional<QuizOptions> quiz;
  /// The in-plane guidance; empty: none (vision only, or the quiz): the paper force alone.
  std::optional<ConditionGuidance> guidance;
  /// The guidance's parameters by name as the protocol gives them (recorded with every trial), read into
  /// `guidance` by `condition_from_mode`.
  std::map<std::string, double> guidance_parameters;
  /// A replay's teacher's recording of an item (teacher_recording.hpp), by item; the path as given,
  /// relative to the protocol file. An item without one gets a teacher recorded by the session runner.
  std::map<std::u32string, std::string> teachers{};
};

/// The condition a protocol's "mode" spells, with its `parameters` (the keys of docs/experiments.md, each in
/// its law's or rule's table range) applied to the law and schedule: e.g. fading: FadingGuidance{start_gain}
/// and a fading schedule from start_gain, forgetting_factor and error_gain_per_m. `guidance_parameters`
/// holds `parameters`. Throws InvalidArgument naming a key the mode does not take or a value out of range.
[[nodiscard]] StudyCondition condition_from_mode(ConditionMode mode,
                                                 const std::map<std::string, double>& parameters = {});

/// The mode that spells `condition` in a protocol, the records and the tables: `quiz` when it quizzes,
/// `vision` without guidance, else by its schedule (fading, assist-as-needed, skill-adaptive) or, without
/// one, by its law (FixedGuidance: haptic; each other law: its mode).
[[nodiscard]] ConditionMode condition_mode(const StudyCondition& condition) noexcept;

/// Whether trials of `condition` replay a teacher's recording (its law is a ReplayGuidance).
[[nodiscard]] inline bool replays_teacher(const StudyCondition& condition) noexcept {
  return condition.guidance && std::holds_alternative<ReplayGuidance>(condition.guidance->law);
}

/// A condition's "mode" (its spelling from EnumTable<ConditionMode>), read through this schema by the
/// protocol reader and described by `calligraphy schema protocol`: reading it sets the condition to
/// `condition_from_mode`'s, writing it gives `condition_mode`. Its parameters are read by its mode's laws'
/// and rules' tables, its name as a label.
template <>
struct SchemaOf<StudyCondition> {
  static const Schema& get();
};

/// How the blocks of conditions are ordered for a subject.
enum class ConditionOrder {
  fixed,         ///< as listed, for every subject
  latin_square,  ///< a balanced Latin square (Williams 1949), row by subject number
  abba,          ///< conditions forwards then backwards (A B B A), reversed for every second subject
  random,        ///< shuffled per subject from the protocol's seed and the subject id
};
/// How the characters are ordered within each round of a block.
enum class ItemOrder {
  fixed,   ///< as listed
  random,  ///< shuffled per subject, block and round from the protocol's seed
};
template <>
struct EnumTable<ConditionOrder> {
  static constexpr std::string_view name = "ConditionOrder";
  static constexpr std::array<EnumEntry<ConditionOrder>, 4> entries{{
      {ConditionOrder::fixed, "fixed", "as listed, for every subject"},
      {ConditionOrder::latin_square, "latin_square",
       "a balanced Latin square (Williams 1949), row by subject"},
      {ConditionOrder::abba, "abba", "forwards then backwards, reversed for every second subject"},
      {ConditionOrder::random, "random", "shuffled per subject from the protocol's seed and the subject id"},
  }};
};
template <>
struct EnumTable<ItemOrder> {
  static constexpr std::string_view name = "ItemOrder";
  static constexpr std::array<EnumEntry<ItemOrder>, 2> entries{{
      {ItemOrder::fixed, "fixed", "as listed"},
      {ItemOrder::random, "random", "shuffled per subject, block and round from the protocol's seed"},
  }};
};
/// The spellings of EnumTable.
[[nodiscard]] const char* to_string(ConditionOrder order) noexcept;
[[nodiscard]] const char* to_string(ItemOrder order) noexcept;

/// The phases of a motor-learning study (Schmidt & Lee, Motor Control and Learning, ch. 9: acquisition,
/// then retention and transfer tests), and the two of a protocol of the paper's design (section 7.1).
enum class StudyPhase {
  practice,   ///< familiarisation with the system ("participants are allowed to write ... a few times")
  test,       ///< the paper's test blocks: conditions compared within one sitting
  pre_test,   ///< performance before any training
  training,   ///< acquisition: practice under the training condition(s)
  post_test,  ///< right after training
  retention,  ///< after a stated delay, on trained characters
  transfer,   ///< on characters not trained
};
template <>
struct EnumTable<StudyPhase> {
  static constexpr std::string_view name = "StudyPhase";
  static constexpr std::array<EnumEntry<StudyPhase>, 7> entries{{
      {StudyPhase::practice, "practice", "familiarisation with the system"},
      {StudyPhase::test, "test", "the paper's test blocks: conditions compared within one sitting"},
      {StudyPhase::pre_test, "pre-test", "performance before any training"},
      {StudyPhase::training, "training", "acquisition: practice under the training condition(s)"},
      {StudyPhase::post_test, "post-test", "right after training"},
      {StudyPhase::retention, "retention", "after a stated delay, on trained characters"},
      {StudyPhase::transfer, "transfer", "on characters not trained"},
  }};
};
/// "practice", "test", "pre-test", "training", "post-test", "retention", "transfer" (EnumTable).
[[nodiscard]] const char* to_string(StudyPhase phase) noexcept;

/// How the conditions of a phase are given to subjects.
enum class ConditionAssignment {
  within_subjects,   ///< every subject writes every condition, in blocks ordered by the protocol's order
  between_subjects,  ///< each subject writes one: the group of `subject_group`
  /// every subject writes every condition, each on another of the phase's item sets, in an order and with
  /// a pairing of conditions and sets counterbalanced by subject number (`crossover_assignment`,
  /// schedule.hpp): a within-subjects comparison of learning, in which no item is trained twice
  crossover,
};
template <>
struct EnumTable<ConditionAssignment> {
  static constexpr std::string_view name = "ConditionAssignment";
  static constexpr std::array<EnumEntry<ConditionAssignment>, 3> entries{{
      {ConditionAssignment::within_subjects, "within-subjects", "every subject writes every condition"},
      {ConditionAssignment::between_subjects, "between-subjects", "each subject writes its group's one"},
      {ConditionAssignment::crossover, "crossover",
       "every subject writes every condition, each on another item set, counterbalanced"},
  }};
};
/// "within-subjects", "between-subjects", "crossover" (EnumTable).
[[nodiscard]] const char* to_string(ConditionAssignment assignment) noexcept;

/// A transfer set chosen by typical-stroke coverage (`choose_transfer_characters`) when a session is made.
struct TransferChoice {
  std::size_t count = 1;                   ///< characters chosen, >= 1
  std::vector<std::u32string> candidates;  ///< single characters to choose from, in order of preference
};

/// A named set of items (a protocol's "item_sets"): the unit a crossover phase trains under one condition, so
/// that every item is attributed to one condition (format: docs/experiments.md, "Crossover designs").
struct ItemSet {
  std::string name;                   ///< unique label: [A-Za-z0-9_-], 1..32 characters
  std::vector<std::u32string> items;  ///< as a phase's items; no character is in two sets
  /// "" or the name of another set (itself without `transfer_of`) whose transfer items these are: they
  /// take that set's condition and period in the tables (PlannedTrial::trained_condition).
  std::string transfer_of;
};

/// One phase of a protocol: its characters written in one or more conditions, a number of rounds each.
struct ProtocolPhase {
  StudyPhase kind = StudyPhase::test;
  std::vector<std::string> conditions;  ///< names of the protocol's conditions, in listed order
  ConditionAssignment assignment = ConditionAssignment::within_subjects;
  /// Each item is written in one trial (one or more characters); empty while `choice` is not resolved.
  std::vector<std::u32string> items;
  std::optional<TransferChoice> choice;  ///< `transfer` only: items chosen when a session is made
  /// The item sets the phase gives ("sets", names of StudyProtocol::item_sets, in listed order), whose items
  /// concatenated are `items`; empty when the phase lists its characters.
  std::vector<std::string> sets;
  /// Parallel to `items` when `sets` is given, or when a test phase beside a crossover lists characters (the
  /// set holding each item's characters): the set of each item; empty otherwise.
  std::vector<std::string> item_sets;
  int repetitions = 1;  ///< times each item is written in each condition, >= 1
  /// 1-based: the session (a sitting, usually a day) the phase is written in. A later session is its own
  /// folder, linked to the subject's previous one (session_series.hpp).
  int session = 1;
  /// The phase starts at least this long after the previous phase ended [s]; for the first phase of a
  /// later session, after the previous session's last trial. Within a session it is a rest.
  double delay_s = 0.0;
  std::string pointer;  ///< where the protocol file gives it ("/test", "/phases/2"): for messages
  /// Items written in the phase: `choice->count` when the choice is not resolved yet.
  [[nodiscard]] std::size_t item_count() const noexcept {
    return choice && items.empty() ? choice->count : items.size();
  }
};

/// A phase's settings besides its conditions and items: "phase", "assignment", "repetitions", "session" and
/// "delay_s", their spellings and ranges written once here (schema.hpp), read by the protocol reader (the
/// paper's "practice" and "test" take its "repetitions") and described by `calligraphy schema protocol`.
template <>
struct SchemaOf<ProtocolPhase> {
  static const Schema& get();
};

/// Rests between trials [s]. Breaks are taken by a person; a simulated writer only logs them.
struct BreakRules {
  double between_blocks_s = 0.0;  ///< before the first trial of every block after the first
  int every_trials = 0;           ///< a rest of `duration_s` after every this many trials; 0: none
  double duration_s = 0.0;
};

/// Settings of every trial of the study (ranges: `SchemaOf<ProtocolTrialSettings>`).
struct ProtocolTrialSettings {
  double max_duration_s = 120.0;  ///< a trial ends after this much device time [s]: TrialSpec's range
  double rate_hz = 1000.0;  ///< servo rate [Hz], the real-time range; x max_duration_s <= kMaxTrialTicks
};

/// The schemas of a protocol's "trial" and "breaks" objects (schema.hpp), read with `schema_from_json`:
/// `max_duration_s` takes TrialSpec's range, `rate_hz` the real-time servo range (a person may write).
template <>
struct SchemaOf<ProtocolTrialSettings> {
  static const Schema& get();
};
template <>
struct SchemaOf<BreakRules> {
  static const Schema& get();
};

/// The range of a replay condition's "max_lead_m": ReplayGuidance's table narrowed to the trial's
/// R_res (ForceLawParameters::constraint_radius_m, which a protocol does not change), the bound a trial
/// checks (guidance_law.hpp), so that a protocol a trial would refuse is refused when read.
[[nodiscard]] ParameterRange protocol_max_lead_range() noexcept;

/// The JSON Schema (draft 2020-12) of a protocol file (`calligraphy schema protocol`): the trial settings
/// and breaks from their schemas, every guidance parameter, the guidance stiffness, the quiz's tolerances
/// from their laws' and rules' tables, and the counts and names from the reader's own limits. Rules between
/// values (names defined, sets disjoint, phases in order, the plan's size) are the reader's alone.
[[nodiscard]] std::string protocol_json_schema_text();
/// The trial settings and breaks as the documentation's Markdown tables.
[[nodiscard]] std::string protocol_schema_markdown();

/// A whole protocol.
struct StudyProtocol {
  std::string name;  ///< [A-Za-z0-9_-], 1..64 characters; names session folders
  std::string description;
  std::vector<StudyCondition> conditions;
  /// In order. The paper's format ("practice" and "test") reads as a `practice` and a `test` phase.
  std::vector<ProtocolPhase> phases;
  /// The protocol's "item_sets", in listed order (0 to 26); empty when it gives none.
  std::vector<ItemSet> item_sets;
  ConditionOrder condition_order = ConditionOrder::fixed;
  ItemOrder item_order = ItemOrder::fixed;
  std::uint64_t seed = 0;  ///< seeds the random orders
  BreakRules breaks;
  ProtocolTrialSettings trial;

  /// The condition called `name`; throws InvalidArgument naming it when there is none.
  [[nodiscard]] const StudyCondition& condition(std::string_view name) const;
  /// The item set called `name`, or nullptr when there is none.
  [[nodiscard]] const ItemSet* item_set(std::string_view name) const noexcept;
  /// The protocol's crossover phase (ConditionAssignment::crossover; at most one), or nullptr.
  [[nodiscard]] const ProtocolPhase* crossover_phase() const noexcept;
  /// Sessions the phases span (the largest `ProtocolPhase::session`), >= 1.
  [[nodiscard]] int session_count() const noexcept;
  /// The characters of the `training` phases, or of every phase when there is none (each once, in order).
  [[nodiscard]] std::u32string trained_characters() const;
};

/// The schema of a protocol's "order" object, on StudyProtocol's members: "conditions" (condition_order),
/// "characters" (item_order) and "seed".
[[nodiscard]] const Schema& protocol_order_schema();

/// Most trials one session of a protocol may plan: 1,000,000 (at 10 s a trial, 116 days of writing; the
/// paper's study plans 26). A session's plan is held in memory and in its session.json, so a protocol within
/// every other bound (1,000 strings x 26 conditions x 1,000 repetitions: 26,000,000 trials) is refused
/// rather than run out of memory.
inline constexpr std::uint64_t kMaxPlannedTrials = 1'000'000;

/// The number of trials the largest session of `protocol` plans: per phase, strings x conditions (one when
/// between subjects) x repetitions, a crossover phase its items (each set once) x repetitions, computed
/// without allocating anything per trial.
[[nodiscard]] std::uint64_t planned_trial_count(const StudyProtocol& protocol) noexcept;

/// `count` with thousands separators ("26,000,000").
[[nodiscard]] std::string thousands(std::uint64_t count);

/// A protocol's content refused by its reader: one line "SOURCE: /json/pointer: what is wrong" (malformed
/// JSON by its byte offset). A usage error of the command line (exit 2), unlike a protocol file that cannot
/// be read at all (a DataError: missing, not a regular file, too large, an I/O error; exit 1).
class ProtocolError : public InputError {
 public:
  using InputError::InputError;
};

/// Parses a protocol. `source` names the text in errors (a file name). Throws ProtocolError naming the
/// source and the JSON pointer of the offending value (e.g. "paper.json: /test/repetitions: expected an
/// integer >= 1, got 0"): malformed JSON (with the byte offset), a missing or unknown key, a value of
/// the wrong type or out of range, a condition named twice or not defined, a character list that is
/// empty or not UTF-8, repetitions that `abba` cannot split evenly, a plan of more than kMaxPlannedTrials
/// trials (the message states the plan's size, e.g. "26,000,000 trials planned"); for "phases": sessions
/// out of order, a pre-test after training, a post-test, retention or transfer test before it, a retention
/// test without a delay or on characters not trained, a transfer test on characters trained, a
/// between-subjects phase of one condition; for "item_sets": a name twice, a character in two sets, a
/// `transfer_of` that names no set, itself or a transfer set, a phase naming an unknown set or giving both
/// or neither of "characters" and "sets"; a crossover phase in practice, without one set per condition (two
/// or more), on a transfer set, or after another crossover phase; beside a crossover phase, another training
/// phase on an item of a set it trains (or of their transfer sets), a test phase's listed character in no set
/// or an item of two sets, and a transfer test chosen by coverage. A test phase beside a crossover that lists
/// its characters gets each item's set in `ProtocolPhase::item_sets` (`sets` stays empty).
[[nodiscard]] StudyProtocol parse_study_protocol(std::string_view json_text, const std::string& source);

/// A protocol read from a file, with the exact text and its SHA-256 (so that a trial names the protocol
/// it ran under and any change to the file is seen).
struct LoadedProtocol {
  StudyProtocol protocol;
  std::string text;    ///< the file's bytes
  std::string sha256;  ///< lower-case hex SHA-256 of `text` (FIPS 180-4)
  std::filesystem::path path;
};

/// Largest protocol file read: 1 MiB.
inline constexpr std::uintmax_t kMaxProtocolBytes = std::uintmax_t{1} << 20;

/// Reads and parses a protocol file. Throws DataError naming the path when it does not exist, is not a
/// regular file, is larger than kMaxProtocolBytes or cannot be read, and ProtocolError as
/// `parse_study_protocol`.
[[nodiscard]] LoadedProtocol load_study_protocol(const std::filesystem::path& path);

/// The protocol from its text (e.g. the copy a session folder keeps): parses it and hashes it.
[[nodiscard]] LoadedProtocol protocol_from_text(std::string text, const std::filesystem::path& path);

}  // namespace calligraphy
