// `calligraphy session run PROTOCOL ...` and `calligraphy session resume DIR`: a study session (or one per
// simulated subject) through the study module's runner, which saves every trial as it ends. SIGINT and
// SIGTERM stop the session after keeping the running trial as an attempt; `resume` goes on from there.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/study/cohort.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/study/session_series.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/interrupt.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/session_plan.hpp"
#include "cli/signals.hpp"
#include "cli/study_inputs.hpp"
#include "cli/writer_options.hpp"
#ifdef CALLIGRAPHY_WITH_TRAINER
#include "trainer/trainer.hpp"
#endif

namespace calligraphy::cli {
namespace {

// Where a person's session is shown: the trainer window (when built with it) or the terminal.
struct SessionDisplay {
  std::string display = "window";
  std::string screenshot;
  double exit_after_s = 0.0;
  bool engineer = false;
};

struct SessionRunCommand {
  std::string protocol;
  std::string subject;
  std::int64_t subject_number = 0;
  const CLI::Option* subject_number_option = nullptr;
  std::int64_t subjects = 0;
  std::string device = "simulated";
  std::string writer;  // person or simulated; empty: the device's own (writer_for_device)
  std::string writer_profile = "novice";
  const CLI::Option* profile_option = nullptr;
  // A simulated subject of a learning study learns, as in `session cohort`; a person's own learning is
  // not modelled, so a person's session records "none" unless the option asks otherwise (refused).
  std::string writer_learning = "two-state";
  const CLI::Option* learning_option = nullptr;
  std::string individual_differences = "on";
  std::string pacing = "auto";
  std::string out;
  bool ignore_delay = false;
  bool new_subjects = false;
  LibraryOptions library;
  SessionDisplay display;
};

struct SessionResumeCommand {
  std::string folder;
  std::string pacing;
  LibraryOptions library;
  SessionDisplay display;
};

// Tells the person at the device what to write next (on stderr: stdout carries the summary) and waits for
// Enter when a terminal is attached; breaks count down.
class TerminalHost final : public SessionHost {
 public:
  void before_trial(const PlannedTrial& trial, std::size_t total) override {
    std::fprintf(stderr, "trial %zu/%zu (%s, %s, repetition %d): write %s", trial.index + 1, total,
                 to_string(trial.phase), trial.condition.c_str(), trial.repetition,
                 encode_utf8(trial.characters).c_str());
    if (::isatty(STDIN_FILENO)) {
      std::fprintf(stderr, " -- press Enter to start\n");
      int c = 0;
      while ((c = std::getchar()) != '\n' && c != EOF && !stop_requested()) {
      }
    } else {
      std::fprintf(stderr, "\n");
    }
  }
  void rest(double seconds, const PlannedTrial&, const std::function<bool()>& should_stop) override {
    std::fprintf(stderr, "break: %.0f s\n", seconds);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end && !should_stop()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  void after_trial(const PlannedTrial& trial, const TrialOutcome& outcome) override {
    // A trial that wrote no stroke has no deviation: "-", as in every table, never "nan".
    char deviation[32] = "-";
    if (std::isfinite(outcome.mean_deviation_mm))
      std::snprintf(deviation, sizeof deviation, "%.2f mm", outcome.mean_deviation_mm);
    // No writing time when the pen never touched: "-", as in the tables.
    char time[32] = "-";
    if (std::isfinite(outcome.time_s)) std::snprintf(time, sizeof time, "%.1f s", outcome.time_s);
    std::fprintf(stderr, "trial %zu: %s, %s, mean deviation %s%s\n", trial.index + 1,
                 outcome.end_reason.c_str(), time, deviation, outcome.saved ? "" : " (kept as an attempt)");
  }
};

SessionRunOptions run_options(const DeviceRegistry& devices, const LibraryOptions& library, SessionHost* host,
                              std::shared_ptr<CharacterSource>& source) {
  source = std::make_shared<CharacterSource>(library);
  SessionRunOptions options;
  // The force law's default stiffness is fitted to the device by the builder of each whole trial
  // (build_whole_trial, stated_force_law), given the figures of the device the session made.
  options.registry = &devices;
  options.load_character = [source](char32_t c) { return source->load(c); };
  options.should_stop = [] { return stop_requested(); };
  options.stop_reason = [] {
    return stop_signal() != 0 ? std::string(signal_name(stop_signal())) : std::string();
  };
  options.host = host;
  return options;
}

#ifdef CALLIGRAPHY_WITH_TRAINER
// A person's session goes to the trainer window unless --display terminal.
bool in_window(const SessionDisplay& display, TrialWriter writer) {
  return writer == TrialWriter::person && display.display == "window";
}
#endif

// Runs the session in the trainer window (a person writes) or headless, with the terminal as host.
SessionRunResult run_one(SessionFolder& session, const SessionRunOptions& options,
                         const SessionDisplay& display, const LibraryOptions& library) {
#ifdef CALLIGRAPHY_WITH_TRAINER
  if (in_window(display, session.manifest().setup.writer)) {
    trainer::TrainerSessionOptions window;
    window.session = &session;
    window.run = options;
    window.run.host = nullptr;
    const auto source = std::make_shared<CharacterSource>(library);
    window.load_character = [source](char32_t c) {
      trainer::TrainerCharacter character;
      character.model = source->load(c);
      character.utf8 = encode_utf8(c);
      try {
        character.outlines = source->load_outlines(c);
      } catch (const DataError& e) {  // e.g. a store built with `--outlines off`: drawn without outlines
        print_error_line("calligraphy session", "warning",
                         "no stroke outlines for " + character.utf8 + ": " + e.what());
      }
      return character;
    };
    window.screenshot = display.screenshot;
    window.exit_after_s = display.exit_after_s;
    window.engineer = display.engineer;
    window.library_version = CALLIGRAPHY_VERSION;
    return trainer::run_trainer_session(window);
  }
#else
  (void)display;
  (void)library;
#endif
  return run_session(session, options);
}

// Runs the session (run_one); a write that fails mid-run (the disk filled meanwhile, the log cannot be
// written) leaves every saved trial as it was, so its message says how to go on.
SessionRunResult run_resumable(SessionFolder& session, const SessionRunOptions& options,
                               const SessionDisplay& display, const LibraryOptions& library) {
  try {
    return run_one(session, options, display, library);
  } catch (const DataError& e) {
    throw DataError(std::string(e.what()) +
                    "; every trial saved before is kept; resume with: calligraphy session resume " +
                    session.path().string());
  }
}

// Prints one line per session; returns the exit status: 0 when complete, 128 + the signal when stopped
// by one, 1 after a device fault. `command` ("calligraphy session run" or "... resume") names the command in
// the line on standard error, as its other lines do.
int report_run(std::string_view command, const SessionFolder& session, const SessionRunResult& result,
               double seconds) {
  std::printf("%s: %zu of %zu trials saved (%zu now, %zu %s kept) in %s, %.1f s\n",
              session.manifest().setup.subject.id.c_str(), result.saved_before + result.saved_now,
              result.planned, result.saved_now, result.attempts_kept,
              result.attempts_kept == 1 ? "attempt" : "attempts",
              printable_name(session.path().string()).c_str(), seconds);
  std::fflush(stdout);
  const std::string resume =
      "resume with: calligraphy session resume " + printable_name(session.path().string());
  if (result.save_failed) {
    print_error_line(command, "error", result.failure + "; every trial saved before is kept; " + resume);
    return 1;
  }
  if (result.device_failed) {
    print_error_line(command, "error", "the device failed (" + result.failure + "); " + resume);
    return 1;
  }
  if (!result.complete()) {
    const int stopped_by = stop_signal();
    const std::string line =
        std::string(command) + ": stopped" +
        (stopped_by != 0 ? std::string(" by ") + signal_name(stopped_by) : std::string()) + "; " + resume +
        "\n";
    std::fputs(line.c_str(), stderr);
    return stopped_by != 0 ? 128 + stopped_by : 1;
  }
  return 0;
}

// The subjects under the study folder `out` that hold a session of `protocol` (its series begun), by id.
std::vector<std::string> subjects_with_sessions(const std::filesystem::path& out,
                                                const LoadedProtocol& protocol) {
  std::vector<std::string> found;
  std::error_code error;
  if (!std::filesystem::is_directory(out, error)) return found;
  for (const auto& entry : std::filesystem::directory_iterator(out, error)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory(error) || !is_subject_id(name)) continue;
    if (!session_series(out, name, protocol).folders.empty()) found.push_back(name);
  }
  std::sort(found.begin(), found.end());
  return found;
}

// "S01, S02, S03" (the first ten, then how many more).
std::string subject_list(const std::vector<std::string>& ids) {
  constexpr std::size_t kNamed = 10;
  std::string text;
  for (std::size_t i = 0; i < ids.size() && i < kNamed; ++i) text += (i == 0 ? "" : ", ") + ids[i];
  if (ids.size() > kNamed) text += " and " + std::to_string(ids.size() - kNamed) + " more";
  return text;
}

std::vector<std::string> split_profiles(const std::string& text) {
  std::vector<std::string> profiles;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    std::string name = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    try {
      (void)writer_profile(name);
    } catch (const InvalidArgument&) {
      throw UsageError(
          "--writer-profile: expected novice, skilled, foreign or a comma-separated list of "
          "them, got '" +
          text + "'");
    }
    profiles.push_back(name);
    if (comma == std::string::npos) return profiles;
    start = comma + 1;
  }
}

int run_sessions(const SessionRunCommand& command, DeviceRegistry& devices) {
  // From the start: a signal while the study's folders and files are made is seen before the first trial,
  // and a file being written is finished, not cut (docs/cli.md, "session run | resume").
  install_stop_handlers();
#ifdef CALLIGRAPHY_WITH_TRAINER
  if (command.display.display == "window") trainer::register_trainer_devices(devices);  // mouse, mouse-hand
#endif
  const LoadedProtocol protocol = load_study_protocol(command.protocol);
  // Simulated subjects rule out a person before the device is looked at.
  if (command.subjects > 0 && command.writer == kPersonWriter) {
    throw UsageError("--subjects: simulated subjects need --writer simulated");
  }
  // What only the simulated writer takes, refused with a person writing.
  const auto check_writer = [&](TrialWriter writer) {
    const bool person = writer == TrialWriter::person;
    if (person && command.learning_option->count() > 0 && command.writer_learning != "none") {
      throw UsageError("--writer-learning models the simulated writer, not a person (--writer person)");
    }
    if (person && command.profile_option->count() > 0) {
      throw UsageError("--writer-profile applies to the simulated writer, not to a person (--writer person)");
    }
    if (command.subjects > 0 && person) {
      throw UsageError("--subjects: simulated subjects need --writer simulated");
    }
    return writer;
  };
  const DeviceListing found_device = [&] {
    try {
      return find_cli_device(devices, "--device", command.device);
    } catch (const DeviceUnavailable&) {
      // The writer is checked against the kind of device, known whether or not the device can be used now:
      // a pairing it cannot have, or an option a person's session does not take, is the usage error it is
      // (exit 2) before a device that cannot be used (1).
      if (const std::optional<bool> simulated_hand = kind_moved_by_simulated_hand(devices, command.device))
        (void)check_writer(writer_for_device(command.writer, command.device, *simulated_hand));
      throw;
    }
  }();
  const DeviceListing* device = &found_device;
  const TrialWriter writer = check_writer(writer_for_device(command.writer, *device));
  const bool person = writer == TrialWriter::person;
  if (command.subjects == 0 && command.subject.empty()) {
    throw UsageError("--subject: required (or --subjects N with --writer simulated)");
  }
  if (command.subjects > 0 && command.subject_number_option->count() > 0) {
    throw UsageError("--subject-number: simulated subjects are numbered 1 to N");
  }
  const std::vector<std::string> profiles = split_profiles(command.writer_profile);
  // The files: nothing written may replace the protocol, the library or a record saved under --out.
  FilePlan files;
  files.input("PROTOCOL", command.protocol);
  add_library_inputs(files, command.library);
  add_saved_sessions(files, "--out", command.out);
  files.output_folder("--out", command.out);
  files.output("--screenshot", command.display.screenshot);
  const CharacterSource characters(command.library);
  require_characters(protocol, characters);

  const LoadedProtocol resolved = resolved_protocol(protocol, characters);
  const int sessions = resolved.protocol.session_count();
  // The subjects already holding this protocol's sessions under --out: a protocol of one session run again
  // would start their session 1 a second time, and every reader would pool the two.
  const std::vector<std::string> begun = subjects_with_sessions(command.out, resolved);
  const std::string prefix = command.subject.empty() ? "S" : command.subject;
  std::vector<SubjectAssignment> subjects;
  if (command.subjects > 0) {
    try {
      // --new-subjects: numbered after the highest number of this prefix already there.
      std::size_t after = 0;
      if (command.new_subjects) {
        for (const std::string& id : begun) {
          if (id.size() > prefix.size() && id.starts_with(prefix) &&
              id.find_first_not_of("0123456789", prefix.size()) == std::string::npos)
            after = std::max(after, trailing_number(id));
        }
      }
      subjects = numbered_subjects(after + static_cast<std::size_t>(command.subjects), prefix);
      subjects.erase(subjects.begin(), subjects.begin() + static_cast<std::ptrdiff_t>(after));
    } catch (const InvalidArgument& e) {
      throw UsageError(std::string("--subject: ") + e.what());
    }
  } else {
    // The id names a folder under --out: one that is not a label is the option's value refused.
    if (!is_subject_id(command.subject)) {
      throw UsageError("--subject '" + command.subject + "': expected 1 to 64 letters, digits, '_' or '-'");
    }
    const std::size_t number = command.subject_number_option->count() > 0
                                   ? static_cast<std::size_t>(command.subject_number)
                                   : trailing_number(command.subject);
    if (number == 0 && resolved.protocol.crossover_phase() != nullptr) {
      throw UsageError(
          "--subject " + command.subject +
          ": the crossover phase counterbalances by the subject's number (1, 2, ...), and this id "
          "ends in none or in 0; give --subject-number N");
    }
    if (number == 0) {
      // A design that assigns groups or orders by number cannot place a subject without one: the id the user
      // gave is the value at fault (exit 2), found before any folder is made.
      try {
        for (int session = 1; session <= sessions; ++session)
          static_cast<void>(plan_session(resolved.protocol, {command.subject, 0}, session));
      } catch (const InvalidArgument& e) {
        throw UsageError(
            "--subject " + command.subject + ": " + e.what() +
            "; this id ends in none or in 0 (or in more than 9 digits): give --subject-number N");
      }
    }
    subjects.push_back({command.subject, number});
  }
  std::vector<std::string> again;  // subjects of this run whose series is begun under --out
  for (const SubjectAssignment& subject : subjects) {
    if (std::binary_search(begun.begin(), begun.end(), subject.id)) again.push_back(subject.id);
  }
  if (!again.empty() && command.new_subjects) {
    throw UsageError("--new-subjects: " + subject_list(again) + " already holds sessions of '" +
                     resolved.protocol.name + "' under --out " + command.out + ": give a new --subject");
  }
  if (!again.empty() && sessions == 1) {
    throw UsageError("--out " + command.out + " already holds the session of '" + resolved.protocol.name +
                     "' for " + subject_list(again) + ": a run would start " +
                     (again.size() == 1 ? "its" : "their") + " session 1 again; " +
                     (command.subjects > 0
                          ? std::string("--new-subjects runs ") + std::to_string(command.subjects) +
                                " new subjects numbered after those there"
                          : std::string("give a new --subject")) +
                     ", and `calligraphy session resume DIR` goes on with an unfinished session");
  }
  const auto setup_for = [&](std::size_t i, int session_number) {
    SessionSetup setup;
    setup.subject = subjects[i];
    setup.device = command.device;
    setup.writer = writer;
    setup.writer_profile = profiles[i % profiles.size()];
    setup.writer_seed = subject_seed(setup.subject.id);
    setup.writer_learning =
        person ? WriterLearning::none : parse_enum<WriterLearning>(command.writer_learning);
    setup.individual_differences = !person && command.individual_differences == "on";
    setup.pacing = parse_enum<TrialPacing>(command.pacing);
    setup.session_number = session_number;
    return setup;
  };

  // Before any session folder is made, what would otherwise stop the run after some of them:
  // an edited protocol beside sessions of its earlier text (a second series would start beside the first),
  check_protocol_unchanged(command.out, resolved);
  // a replay's teacher's recording that cannot be read or is not the item's (read again when its trial
  // comes),
  check_protocol_teachers(resolved);
  // a session.json larger than its readers take (its size depends on the session and the subject's group
  // only: permutations of one plan are as long),
  std::set<std::pair<int, std::string>> sized;
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    for (int number = 1; number <= sessions; ++number) {
      if (sized.emplace(number, subject_group(resolved.protocol, subjects[i])).second)
        check_session_manifest_size(setup_for(i, number), resolved);
    }
  }
  // and a folder where no trial could be saved (read-only, full).
  for (const SubjectAssignment& subject : subjects) {
    std::filesystem::path existing = std::filesystem::path(command.out) / subject.id;
    std::error_code error;
    while (!std::filesystem::exists(existing, error)) {  // the folder the first write makes a folder in
      if (!existing.has_parent_path()) {
        existing = ".";
        break;
      }
      existing = existing.parent_path();
    }
    if (std::filesystem::is_directory(existing, error))
      check_writable_folder(existing, trial_files_bytes(resolved.protocol.trial));
  }

#ifdef CALLIGRAPHY_WITH_TRAINER
  // and a person's session in the window without a display to open it on (no session folder left behind).
  if (in_window(command.display, writer)) trainer::check_display();
#endif

  // One run into a study folder at a time: the lock is held until this run ends. Another run that was here
  // before it, or ended since the checks above, is seen by checking again under the lock.
  const StudyRunLock study_lock(command.out,
                                "calligraphy session run " + command.protocol + " --out " + command.out);
  check_protocol_unchanged(command.out, resolved);
  if (command.new_subjects || sessions == 1) {
    std::vector<std::string> meanwhile;
    for (const std::string& id : subjects_with_sessions(command.out, resolved)) {
      const bool ours = std::any_of(subjects.begin(), subjects.end(),
                                    [&id](const SubjectAssignment& s) { return s.id == id; });
      if (ours && !std::binary_search(begun.begin(), begun.end(), id)) meanwhile.push_back(id);
    }
    if (!meanwhile.empty()) {
      throw StateError("--out " + command.out + ": another run started the session of '" +
                       resolved.protocol.name + "' for " + subject_list(meanwhile) +
                       " as this one began; nothing was run");
    }
  }

  // What is about to run (stderr: stdout carries one line per session run).
  // After --new-subjects, the balance is the whole study's: subjects 1 to the last one of this run.
  std::vector<SubjectAssignment> study;
  if (command.new_subjects && command.subjects > 0 && subjects.front().number > 1)
    study = numbered_subjects(subjects.back().number, prefix);
  std::fputs(session_plan_text(resolved, subjects, study).c_str(), stderr);
  std::fflush(stderr);

  TerminalHost host;
  std::shared_ptr<CharacterSource> source;
  const SessionRunOptions options = run_options(devices, command.library, person ? &host : nullptr, source);
  for (std::size_t i = 0; i < subjects.size(); ++i) {
    // The subject's series: a simulated subject writes every remaining session in a row (the delays taken
    // as passed), a person the next one, when its delay has passed.
    while (true) {
      if (stop_requested()) {
        print_error_line("calligraphy session run", "error",
                         subjects[i].id + ": stopped by " + signal_name(stop_signal()) +
                             " before its session began; nothing written for it");
        return 128 + stop_signal();
      }
      // Held until this session is written: another run of the subject waits, then sees it.
      std::optional<SeriesLock> lock;
      {
        lock.emplace(
            command.out, subjects[i].id,
            [&](const std::filesystem::path& path) {
              std::fprintf(stderr, "%s: waiting for another run of this subject to end (%s)\n",
                           subjects[i].id.c_str(), path.c_str());
            },
            [] { return stop_requested(); });
        if (!lock->held()) {
          print_error_line("calligraphy session run", "error",
                           subjects[i].id + ": stopped by " + signal_name(stop_signal()) +
                               " while waiting for another run of this subject; nothing written for it");
          return 128 + stop_signal();
        }
      }
      // A protocol of one session is a series of one: a subject whose session is there is done.
      const SessionSeries series = session_series(command.out, subjects[i].id, resolved);
      if (series.unfinished) {
        throw StateError(
            subjects[i].id + ": session " + std::to_string(series.next) + " of " + protocol.protocol.name +
            " is not finished; resume it first: calligraphy session resume " + series.unfinished->string());
      }
      if (series.next > sessions) {
        std::printf("%s: every session of %s is done (%d)\n", subjects[i].id.c_str(),
                    protocol.protocol.name.c_str(), sessions);
        break;
      }
      std::optional<PreviousSession> previous = series.previous;
      if (series.ended_in_future() && person && !command.ignore_delay) {
        throw StateError(subjects[i].id + ": session " + std::to_string(series.next - 1) + " of " +
                         protocol.protocol.name + " ended " + previous->ended_utc + " (" +
                         series.previous_record.string() + "), " +
                         std::to_string(static_cast<long long>(-previous->elapsed_s)) +
                         " s after now by this computer's clock: another or a wrong clock. --ignore-delay "
                         "starts it now (recorded as overridden, the elapsed time as measured)");
      }
      if (previous && !series.due()) {
        if (!person) {
          previous->delay = SessionDelay::simulated;
        } else if (command.ignore_delay) {
          previous->delay = SessionDelay::overridden;
        } else {
          throw StateError(
              subjects[i].id + ": session " + std::to_string(series.next) + " of " + protocol.protocol.name +
              " is due " + shortest_decimal(previous->delay_s) + " s after session " +
              std::to_string(series.next - 1) + " ended (" + previous->ended_utc + "); " +
              // rounded up: "0 s to go" of a session not yet due would say it is
              std::to_string(static_cast<long long>(std::ceil(previous->delay_s - previous->elapsed_s))) +
              " s to go. --ignore-delay starts it now (recorded as overridden)");
        }
      }
      SessionFolder session =
          SessionFolder::create(command.out, setup_for(i, series.next), resolved, previous);
      const auto start = std::chrono::steady_clock::now();
      const SessionRunResult result = run_resumable(session, options, command.display, command.library);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const int status = report_run("calligraphy session run", session, result, seconds);
      if (status != 0) return status;
      if (person || sessions == 1) break;
    }
  }
  return 0;
}

// The characters a resumed session goes on with are the ones its saved trials were written with: each saved
// record's placed characters (scene SHA-256) against the same characters loaded now and placed as recorded.
// Other data (a session run with --store or --data, resumed without it, or with another folder or store) is
// refused naming the record and the character, before the first trial: one session, one shape per character.
void require_same_characters(const SessionFolder& session, const CharacterSource& source) {
  std::set<std::u32string> checked;  // one saved record per item: its characters are placed alike in each
  for (const PlannedTrial& trial : session.plan()) {
    if (!session.is_saved(trial) || !checked.insert(trial.characters).second) continue;
    const std::string path = session.trial_file(trial, "json").string();
    const RecordedTrial recorded = read_recorded_trial_file(path);
    if (recorded.scene_sha256.empty()) continue;  // a record that states no placed characters
    std::vector<Character> characters;
    for (const char32_t c : trial.characters) characters.push_back(source.load(c));
    if (scene_is_recorded_one(Scene::lay_out(characters, recorded.layout), recorded.scene_sha256)) continue;
    throw DataError(
        path + ": " + encode_utf8(trial.characters) +
        " was written with other character data "
        "than --data or --store give now (scene SHA-256 " +
        recorded.scene_sha256.substr(0, 12) +
        "... in the record); resume with the option the session ran with; nothing was run or written");
  }
}

int resume_session(const SessionResumeCommand& command, DeviceRegistry& devices) {
  install_stop_handlers();  // from the start, as `session run`
#ifdef CALLIGRAPHY_WITH_TRAINER
  if (command.display.display == "window") trainer::register_trainer_devices(devices);
#endif
  // Saved records are inputs: no output may replace one.
  FilePlan files;
  files.input_folder("DIR", command.folder);
  add_library_inputs(files, command.library);
  files.output("--screenshot", command.display.screenshot);
  // One run writes into a study folder at a time: a resume takes the study's run lock as `session run`
  // does (DIR/../..), so that a run and a resume, or two resumes, never write one study at once.
  std::error_code resolved_error;
  std::filesystem::path folder = std::filesystem::weakly_canonical(command.folder, resolved_error);
  if (resolved_error || folder.empty()) folder = std::filesystem::absolute(command.folder).lexically_normal();
  if (!folder.has_filename()) folder = folder.parent_path();
  const std::filesystem::path study_root = folder.parent_path().parent_path();
  // Only over a session folder that is there: a missing one is SessionFolder::open's error, and no folder is
  // made for it.
  std::optional<StudyRunLock> study_lock;
  if (std::filesystem::is_directory(folder, resolved_error) &&
      std::filesystem::is_directory(study_root, resolved_error))
    study_lock.emplace(study_root, "calligraphy session resume " + command.folder);
  SessionFolder session = SessionFolder::open(command.folder);
  // A session of another study, copied into this study folder, is not this study's to go on with.
  StudyIdentity::check(StudyIdentity::read(study_root), study_root, session.path(), session.manifest());
  // Each saved record read as `trial --spec` reads it, whether trials are left or not: one cut or emptied
  // since is the folder's content refused (InputError, exit 2), named now rather than by the next reader of
  // the study, and never called saved.
  for (const PlannedTrial& trial : session.plan()) {
    if (session.is_saved(trial)) (void)read_recorded_trial_file(session.trial_file(trial, "json").string());
  }
  // A folder renamed since its first trial was saved: its records name the old id (the folder's name).
  session.check_records_name_this_session();
  require_characters(session.manifest().protocol, CharacterSource(command.library));
  if (!session.next_unsaved()) {
    // A run killed after its last save and before it logged the end: the log is completed, once.
    (void)complete_session_log(session);
    std::printf("%s: every trial of %s is saved already\n", session.manifest().setup.subject.id.c_str(),
                session.path().c_str());
    return 0;
  }
  check_not_followed(session);
  require_same_characters(session, CharacterSource(command.library));
  session.check_writable();  // before the first trial: a folder no trial could be saved in
  TerminalHost host;
  std::shared_ptr<CharacterSource> source;
  SessionRunOptions options =
      run_options(devices, command.library,
                  session.manifest().setup.writer == TrialWriter::person ? &host : nullptr, source);
  if (!command.pacing.empty()) {
    options.pacing = parse_trial_pacing(command.pacing, "--pacing");
  }
  const auto start = std::chrono::steady_clock::now();
  const SessionRunResult result = run_resumable(session, options, command.display, command.library);
  return report_run("calligraphy session resume", session, result,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace

void add_display_options(CLI::App& app, SessionDisplay& display) {
  add_choice(app, "--display", display.display, {"window", "terminal"},
             "where a person's session is shown: the trainer window (trial by trial, live; needs the "
             "trainer build, else the terminal) or the terminal");
  add_output_path(app, "--screenshot", display.screenshot,
                  "window: write it as PNG after the last planned trial's outcome, or at exit",
                  StandardOutput::refused);
  add_number(
      app, "--exit-after", display.exit_after_s, "SECONDS",
      "window, unattended: trials start by themselves; quit after this long [s, (0, 86400]] or at the end",
      "a number of seconds in (0, 86400]", [](double s) { return s > 0.0 && s <= 86400.0; }, "none");
  add_flag(app, "--engineer", display.engineer,
           "window: the engineer's panel (interaction state, ticks, elements, pen and force); without it the "
           "learner's view (docs/trainer.md)");
}

void add_session_commands(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  CLI::App* group = commands.add_group(
      root, "session", "Study sessions: run a protocol, resume a stopped session, simulate a cohort");

  auto run = std::make_shared<SessionRunCommand>();
  CLI::App* app = commands.add(
      *group, "run",
      "Run a study protocol for one subject, or for N simulated subjects; SIGINT or SIGTERM stops it "
      "after keeping the running trial (exit status 128 + the signal)",
      [run, &devices] { return run_sessions(*run, devices); });
  add_positional(*app, "PROTOCOL", run->protocol, "the study protocol (JSON; docs/experiments.md)", "FILE");
  add_text(*app, "--subject", run->subject, "ID",
           "the subject's id (letters, digits, '_', '-'); with --subjects, the prefix of the simulated ids",
           "required; with --subjects: S");
  run->subject_number_option =
      add_integer(*app, "--subject-number", run->subject_number, "N",
                  "the subject's number for counterbalancing (Latin square row, ABBA direction)", 1,
                  1000000000, "the digits ending --subject");
  add_integer(
      *app, "--subjects", run->subjects, "N",
      "run N simulated subjects ID01..IDN, numbered 1..N, one session each (needs --writer simulated)", 1,
      1000, "none");
  add_text(*app, "--device", run->device, "NAME", "the device, by its name in `calligraphy devices`");
  add_writer_option(*app, run->writer,
                    "who writes: the simulated writer (on the simulated and emulated devices it moves) or a "
                    "person (on hardware, or mouse and mouse-hand in the window)",
                    "simulated on a simulated or emulated device, person on hardware");
  run->profile_option = add_text(
      *app, "--writer-profile", run->writer_profile, "PROFILES",
      "the simulated writer's profile, novice, skilled or foreign; a comma-separated list is used by subject "
      "in turn");
  run->learning_option = add_choice(
      *app, "--writer-learning", run->writer_learning, enum_choices<WriterLearning>(),
      "how a simulated subject learns: none (every trial from its profile) or two-state (a memory per "
      "typical stroke and character that practice builds and time between sessions thins; docs/writer.md), "
      "as `session cohort`; a person's session records none");
  add_choice(*app, "--individual-differences", run->individual_differences, {"on", "off"},
             "on: each simulated subject draws its own baseline skill, motor noise and learning rates from "
             "its id (docs/writer.md); off: every subject is the profile itself");
  add_choice(*app, "--pacing", run->pacing, enum_choices<TrialPacing>(),
             "auto: lock-step for a simulated writer, real time for a person; real-time paces a simulated "
             "writer by the wall clock");
  required(
      add_text(*app, "--out", run->out, "DIR",
               "the study folder: sessions go to DIR/SUBJECT/PROTOCOL-SUBJECT-TIME/; a protocol of several "
               "sessions goes on with the subject's next one there"));
  add_flag(*app, "--new-subjects", run->new_subjects,
           "with --subjects N: run N new subjects, numbered after the highest of the --subject prefix that "
           "holds sessions of the protocol under --out; a subject given by --subject must be new");
  add_flag(*app, "--ignore-delay", run->ignore_delay,
           "start a person's next session before the protocol's delay has passed, or after a session that "
           "ended later than now by this computer's clock (recorded as overridden)");
  add_library_options(*app, run->library, true);
  add_display_options(*app, run->display);

  add_session_cohort_command(*group, commands);
  add_session_plan_command(*group, commands);

  auto resume = std::make_shared<SessionResumeCommand>();
  CLI::App* resume_app =
      commands.add(*group, "resume", "Go on with a stopped or crashed session from its first unsaved trial",
                   [resume, &devices] { return resume_session(*resume, devices); });
  add_positional(*resume_app, "DIR", resume->folder, "the session folder (the one holding session.json)",
                 "DIR");
  add_choice(*resume_app, "--pacing", resume->pacing, enum_choices<TrialPacing>(),
             "overrides the pacing the session was started with", "the session's own pacing");
  add_library_options(*resume_app, resume->library, true);
  add_display_options(*resume_app, resume->display);
}

}  // namespace calligraphy::cli
