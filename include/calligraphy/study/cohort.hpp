#pragma once
/// \file cohort.hpp
/// A simulated cohort: simulated subjects through every session of a protocol in memory, without session
/// folders, logs, traces or per-trial files, as a simulation study of many subjects needs. Each trial is
/// the one a session folder would hold: the same plan (`plan_session`), trial specification
/// (`study_trial_spec`), seed, guidance schedule (a repetition's gain, band or mode from the previous one's
/// record), learning memory (sim/writer_memory.hpp: practised from the trial's record, consolidated between
/// sessions) and metrics record, so that its rows are the rows `read_study_tables` gives for the folders of
/// `calligraphy session run` with the same subjects, profile and learning (docs/experiments.md, "A cohort
/// in memory").
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/study_tables.hpp"

namespace calligraphy {

/// Who the subjects are and where their characters come from.
struct CohortSetup {
  /// The simulated writer's profile (`writer_profile`): "novice", "skilled" or "foreign".
  std::string writer_profile = "novice";
  /// `none` (every trial from the profile) or `two_state` (the learning memory,
  /// SessionSetup::writer_learning).
  WriterLearning writer_learning = WriterLearning::two_state;
  /// Whether the subjects differ from one another (SessionSetup::individual_differences, sim/
  /// subject_traits.hpp); false: every subject is the profile itself.
  bool individual_differences = true;
  /// Loads a character's model; empty: the standard set (CharacterLibrary::standard(): every
  /// hanzi-writer-data character). Called from one thread at a time.
  std::function<Character(char32_t)> load_character;
  /// Asks the cohort to stop (Ctrl-C in Python); empty: never. Polled by every trial's ticks from every
  /// worker thread at once (TrialRunInputs::should_stop), so it must be thread-safe. Once it returns true,
  /// each running trial ends `interrupted` at its next tick, no subject starts, and `simulate_subject` and
  /// `simulate_cohort` throw StateError naming the subject and trial it stopped.
  std::function<bool()> should_stop;
  /// Throws InvalidArgument naming the field for an unknown profile or learning.
  void validate() const;
};

/// The most subjects one cohort simulates (the CLI, Python and the library alike): the tables of more do not
/// fit a computer's memory.
inline constexpr std::size_t kMaxCohortSubjects = 100000;

/// The simulated subjects 1..`count`, with the ids `session run --subjects` gives them: `prefix` and the
/// number in at least two digits ("S01"). Throws InvalidArgument for a count of 0 or above
/// kMaxCohortSubjects, or a prefix that makes no subject id.
[[nodiscard]] std::vector<SubjectAssignment> numbered_subjects(std::size_t count,
                                                               const std::string& prefix = "S");

/// Every session of `protocol` for one simulated subject, in order, the delays between sessions taken as
/// passed. Returns the subject's rows: one `TrialRow` per trial and one `StrokeRow` per reference stroke, as
/// `read_study_tables` reads them from session folders, except that `session` is "PROTOCOL-sN" (N the session
/// number), `start_utc` is empty and there is no trace file. Throws InvalidArgument for a bad setup, a
/// protocol with a replay condition (its teacher is recorded into a session folder: use `session run`) or an
/// unresolved transfer choice (`resolve_transfer_choices`); CharacterNotFound for a character the loader
/// lacks; StateError naming the subject and trial when a trial ends without being kept (a simulated device
/// does not fail, so this is a defect, never a result).
[[nodiscard]] StudyTables simulate_subject(const LoadedProtocol& protocol, const SubjectAssignment& subject,
                                           const CohortSetup& setup);

/// `simulate_subject` for every subject, on `threads` >= 1 threads (each subject on one thread, in turn;
/// the calling thread is one, and a thread the system will not start is done without: RLIMIT_NPROC),
/// the rows in the order of `subjects`. The characters of the protocol are loaded once, before any trial.
/// `progress`, when given, is called after each subject with the number done (from the worker threads, one
/// call at a time). The first error of any subject is thrown once every thread has stopped; no subject
/// starts after it. Throws as `simulate_subject`, and InvalidArgument for 0 threads or more than
/// kMaxCohortSubjects subjects.
[[nodiscard]] StudyTables simulate_cohort(const LoadedProtocol& protocol,
                                          const std::vector<SubjectAssignment>& subjects,
                                          const CohortSetup& setup, unsigned threads = 1,
                                          const std::function<void(std::size_t)>& progress = {});

}  // namespace calligraphy
