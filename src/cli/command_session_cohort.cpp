// `calligraphy session cohort PROTOCOL --subjects N --csv DIR`: N simulated subjects through every session
// of a protocol in memory (study/cohort.hpp), on every core, without session folders; the study's tidy
// tables (trials.csv, strokes.csv) are written at the end, as `report --csv` writes them for folders.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/study/cohort.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/progress.hpp"
#include "cli/study_inputs.hpp"

namespace calligraphy::cli {
namespace {

struct SessionCohortCommand {
  std::string protocol;
  std::int64_t subjects = 0;
  std::string prefix = "S";
  std::string writer_profile = "novice";
  std::string writer_learning = "two-state";
  std::string individual_differences = "on";
  std::int64_t jobs = 0;  // 0: every core
  std::string csv;
  LibraryOptions library;
};

int run_session_cohort(const SessionCohortCommand& command) {
  const auto start = std::chrono::steady_clock::now();
  FilePlan files;
  files.input("PROTOCOL", command.protocol);
  add_library_inputs(files, command.library);
  const std::filesystem::path tables_folder(command.csv);
  files.existing_output_folder("--csv", command.csv);
  files.set_output("--csv", (tables_folder / "trials.csv").string());
  files.set_output("--csv", (tables_folder / "strokes.csv").string());

  const LoadedProtocol protocol = load_study_protocol(command.protocol);
  // A replay's teacher is recorded into a session folder, which a cohort has not: the protocol's content is
  // refused as a design this command cannot run, naming the condition's mode.
  for (std::size_t i = 0; i < protocol.protocol.conditions.size(); ++i) {
    const StudyCondition& condition = protocol.protocol.conditions[i];
    if (!replays_teacher(condition)) continue;
    throw ProtocolError(protocol.path.string() + ": /conditions/" + std::to_string(i) +
                        "/mode: the condition '" + condition.name +
                        "' replays a teacher, which is kept in a session folder; a simulated cohort runs "
                        "without one (run it with calligraphy session run)");
  }
  const CharacterSource characters(command.library);
  require_characters(protocol, characters);
  const LoadedProtocol resolved = resolved_protocol(protocol, characters);
  CohortSetup setup;
  setup.writer_profile = command.writer_profile;
  setup.writer_learning = parse_enum<WriterLearning>(command.writer_learning);
  setup.individual_differences = command.individual_differences == "on";
  setup.load_character = [&characters](char32_t c) { return characters.load(c); };
  std::vector<SubjectAssignment> subjects;
  try {
    subjects = numbered_subjects(static_cast<std::size_t>(command.subjects), command.prefix);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--subject: ") + e.what());
  }
  const unsigned threads = command.jobs > 0 ? static_cast<unsigned>(command.jobs)
                                            : std::max(1u, std::thread::hardware_concurrency());

  TerminalProgress progress("subjects");
  const StudyTables tables = simulate_cohort(resolved, subjects, setup, threads, [&](std::size_t done) {
    progress.update(done, subjects.size(), "subjects");
  });
  // Both tables or neither: a failure leaves the previous pair whole.
  const std::string trials_text = trials_csv(tables), strokes_text = strokes_csv(tables);
  OutputSet table_files;
  table_files.add(tables_folder / "trials.csv", trials_text);
  table_files.add(tables_folder / "strokes.csv", strokes_text);
  table_files.commit();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The threads simulate_cohort runs: one per subject at most.
  const std::size_t used = std::min<std::size_t>(threads, subjects.size());
  std::printf(
      "%s: %zu subjects, %zu trials on %zu %s in %.1f s: trials.csv (%zu rows), strokes.csv (%zu rows)\n",
      printable_name(command.csv).c_str(), subjects.size(), tables.trials.size(), used,
      used == 1 ? "thread" : "threads", seconds, tables.trials.size(), tables.strokes.size());
  return 0;
}

}  // namespace

void add_session_cohort_command(CLI::App& session, Commands& commands) {
  auto command = std::make_shared<SessionCohortCommand>();
  CLI::App* app = commands.add(
      session, "cohort",
      "Run N simulated subjects through every session of a protocol in memory, on every core, and write the "
      "study's tidy tables (no session folders; the same trials as session run)",
      [command] { return run_session_cohort(*command); });
  add_positional(*app, "PROTOCOL", command->protocol, "the study protocol (JSON; docs/experiments.md)",
                 "FILE");
  required(add_integer(*app, "--subjects", command->subjects, "N",
                       "simulated subjects PREFIX01..PREFIXN, numbered 1..N", 1,
                       static_cast<long long>(kMaxCohortSubjects)));
  add_text(*app, "--subject", command->prefix, "PREFIX", "the prefix of the subjects' ids");
  add_choice(*app, "--writer-profile", command->writer_profile, name_choices(writer_profile_names()),
             "the simulated subjects' profile");
  add_choice(*app, "--writer-learning", command->writer_learning, enum_choices<WriterLearning>(),
             "how a subject learns: none (every trial from its profile) or two-state (docs/writer.md)");
  add_choice(*app, "--individual-differences", command->individual_differences, {"on", "off"},
             "on: each subject draws its own baseline skill, motor noise and learning rates from its id "
             "(docs/writer.md); off: every subject is the profile itself");
  add_integer(*app, "--jobs", command->jobs, "N", "threads, each simulating one subject at a time", 1, 1024,
              "every core");
  required(add_output_folder(
      *app, "--csv", command->csv,
      "an existing folder for the tidy tables trials.csv and strokes.csv (docs/experiments.md)", ""));
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
