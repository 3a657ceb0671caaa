#pragma once
/// \file session_folder.hpp
/// The folder of one subject's session, laid out so that no saved trial is ever lost or overwritten:
///
///     ROOT/SUBJECT/PROTOCOL-YYYYMMDD-HHMMSS/
///       session.json          what the session was started with: subject, device, writer, the protocol's
///                             text, path and SHA-256, the library build, and the planned trials
///       log.jsonl             append-only event log, one JSON object a line, fsync'ed line by line
///       trials/NNN-PHASE-CONDITION-rR-U....json|.csv|.svg    one saved trial (the JSON is written last)
///       trials/attempts/...   interrupted or failed attempts, numbered, kept for the record
///
/// A trial counts as saved when its JSON exists. The JSON is committed with link(2) from a complete,
/// fsync'ed temporary file, which fails rather than replace an existing file; the CSV and SVG beside it
/// are written first with `write_file_atomically`. The log is locked (flock) while a process works on the
/// session, so two runners cannot write one session. Format of every file: docs/experiments.md.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy {

/// The current time in UTC as the study's files write it: ISO 8601 with milliseconds,
/// "2024-05-01T12:34:56.789Z" (a record's start_utc and end_utc, the log's time_utc).
[[nodiscard]] std::string utc_now_iso8601();

/// The library that ran a session: version, build type, compiler and C++ standard.
struct LibraryBuild {
  std::string version;       ///< the project's version, e.g. "0.1.0"
  std::string build_type;    ///< CMake build type, e.g. "Release"
  std::string compiler;      ///< e.g. "GCC 12.2.0"
  std::string cxx_standard;  ///< the value of __cplusplus, e.g. "202002"
};
[[nodiscard]] LibraryBuild library_build();

/// How a session is run: kept in session.json so that a resumed session runs the same way.
struct SessionSetup {
  SubjectAssignment subject;
  std::string device = "simulated";  ///< the device's name in the device registry
  /// Who writes: `simulated` (a simulated writer moves the device) or `person`; a session is never
  /// `automatic` (`create` refuses it: the CLI resolves it from the device before).
  TrialWriter writer = TrialWriter::simulated;
  std::string writer_profile = "novice";  ///< the simulated writer's profile (`writer_profile`): "novice",
                                          ///< "skilled" or "foreign"
  std::uint64_t writer_seed = 0;          ///< the simulated subject's seed (see `subject_seed`)
  /// How a simulated subject learns from trial to trial: `none` (each trial from its profile) or `two_state`
  /// (a memory per typical stroke and character, sim/writer_memory.hpp, rebuilt from the saved trials of
  /// this session and the ones before it); a person's session is `none`.
  WriterLearning writer_learning = WriterLearning::none;
  /// Whether a simulated subject differs from the others of its profile (sim/subject_traits.hpp: its own
  /// baseline skill, motor noise and learning rates, drawn from `writer_seed`); false: every subject is the
  /// profile itself. Sessions made before subjects differed read as false.
  bool individual_differences = true;
  TrialPacing pacing = TrialPacing::automatic;
  /// 1-based: which of the protocol's sessions (ProtocolPhase::session) this one is.
  int session_number = 1;
};

/// How the protocol's delay before a session was kept.
enum class SessionDelay : std::uint8_t {
  waited,      ///< elapsed_s >= delay_s
  simulated,   ///< a simulated writer: the delay is taken as passed, not waited
  overridden,  ///< started early on the experimenter's request, or after a session whose end lies in the
               ///< future by this computer's clock (`elapsed_s` then negative, recorded as measured)
};

template <>
struct EnumTable<SessionDelay> {
  static constexpr std::string_view name = "SessionDelay";
  static constexpr std::array<EnumEntry<SessionDelay>, 3> entries{{
      {SessionDelay::waited, "waited", "the delay had passed"},
      {SessionDelay::simulated, "simulated", "a simulated writer: the delay taken as passed"},
      {SessionDelay::overridden, "overridden", "started early on the experimenter's request"},
  }};
};

/// The session before this one in a subject's series of sessions of one protocol (session_series.hpp).
struct PreviousSession {
  std::string session_id;                     ///< its folder's name, beside this one in the subject's folder
  std::string ended_utc;                      ///< when its last trial ended (ISO 8601)
  double delay_s = 0.0;                       ///< the protocol's delay before this session [s]
  double elapsed_s = 0.0;                     ///< from `ended_utc` to this session's creation [s]
  SessionDelay delay = SessionDelay::waited;  ///< how the delay was kept
  /// Lower-case hex SHA-256 of its session.json when this session was made: the content id that tells the
  /// previous session from another one of the same name. Empty for sessions made before it was recorded.
  std::string session_sha256;
};

/// The seed of a simulated subject, derived from its id alone (FNV-1a of the id, mixed by SplitMix64), so
/// that a subject writes the same way in every session and protocol.
[[nodiscard]] std::uint64_t subject_seed(std::string_view subject_id);

struct Schema;

/// The schema of session.json (its root object, SessionManifest as the file lays it out), from which every
/// reader reads it: `calligraphy schema session --markdown` prints its fields.
[[nodiscard]] const Schema& session_manifest_schema();
/// The JSON Schema (draft 2020-12) of session.json (`calligraphy schema session`), made from that schema;
/// the rules between values (the plan's indexes in order, its conditions the protocol's, the protocol copy's
/// SHA-256, a previous session exactly after the first) are the reader's alone.
[[nodiscard]] std::string session_manifest_json_schema_text();

/// What session.json holds.
struct SessionManifest {
  std::string session_id;  ///< the folder's name
  std::string created_utc;
  SessionSetup setup;
  LoadedProtocol protocol;  ///< `text` is the copy kept in session.json; `path` where it was read from
  LibraryBuild library;     ///< the build that created the session
  std::vector<PlannedTrial> plan;
  std::optional<PreviousSession> previous;  ///< sessions after the first: the one before
  std::string group;  ///< the subject's group (`subject_group`): "" when every phase is within subjects
  /// The study folder's identity (`study_id`, the random id of ROOT/.calligraphy-study.json) when the session
  /// was made: a session copied in from another study folder names another. "" in sessions made before
  /// studies had one (read as before).
  std::string study_id;
};

/// A study folder's identity: ROOT/.calligraphy-study.json holds a random id (32 lower-case hex digits,
/// 128 bits from getrandom(2)), made by the first session created under ROOT; every session.json made there
/// records it (`study_id`), so that a session copied in from another study folder, of the same subject and
/// protocol, is not taken as this study's (the series refuses to follow it, the readers to pool it). The file
/// is JSON: {"format": "calligraphy-study", "version": 1, "study_id": ID}.
struct StudyIdentity {
  static constexpr const char* kFileName = ".calligraphy-study.json";
  /// The id of the study folder `root`; nullopt when it has no identity file (a folder made before studies
  /// had one, or none yet). Throws DataError naming the file when it is damaged, not a regular file, or not
  /// this program's.
  [[nodiscard]] static std::optional<std::string> read(const std::filesystem::path& root);
  /// The id of `root`, made when it has none (`write_file_exclusively`: written whole, fsync'ed and linked to
  /// its name, never replacing one, so two runs that make it at once agree on the one linked first). Throws
  /// DataError as `read`, and naming the file when it cannot be written.
  [[nodiscard]] static std::string obtain(const std::filesystem::path& root);
  /// Refuses the session in `folder` (its session.json read as `manifest`) when it names another study than
  /// `root_id`, the id of the study folder it lies in: copied in from another study folder; also when it
  /// names one and the folder has none (copied into a folder made before identities, or the folder's
  /// identity file lost), and when it is this study's but lies in another subject's folder than its own
  /// (ROOT/SUBJECT/). A session without an id (made before studies had one) is accepted. Throws DataError
  /// naming the session.json, its /study_id and the ids, or the missing identity file, or its /subject/id.
  static void check(const std::optional<std::string>& root_id, const std::filesystem::path& root,
                    const std::filesystem::path& folder, const SessionManifest& manifest);
};

/// The largest session.json: every reader of a session (resume, the series, the report and the tables)
/// refuses a larger one, so `SessionFolder::create` refuses to write one. Its plan makes it big: about 250
/// bytes a planned trial, so some 250,000 trials a session.
inline constexpr std::uintmax_t kMaxSessionManifestBytes = std::uintmax_t{64} << 20;

/// Throws DataError naming the protocol's file, the subject, the session and the size when the session.json
/// `SessionFolder::create` would write for `setup` (the plan of `protocol` for its subject and session) is
/// larger than kMaxSessionManifestBytes. A front end checks this before its first session folder is made.
void check_session_manifest_size(const SessionSetup& setup, const LoadedProtocol& protocol);

/// Reads each teacher's recording a replay condition of `protocol` names (`StudyCondition::teachers`,
/// relative to the protocol file) as the session runner will read it when its trial comes: a regular file of
/// at most kMaxTeacherRecordingBytes, a teacher's recording (`parse_teacher_recording`) of its item. Throws
/// InvalidArgument or DataError naming the condition and the file. A front end checks this before its first
/// session folder is made, so that a protocol refused there makes none.
void check_protocol_teachers(const LoadedProtocol& protocol);

/// The free space kept for one trial's files (its compressed trace, SVG and record, and their temporaries):
/// 64 bytes a servo tick of a trial at its time limit (`max_duration_s` x `rate_hz`; the trace's CSV before
/// compression takes about that, the compressed trace, SVG and record together far less) plus 1 MiB.
[[nodiscard]] std::uintmax_t trial_files_bytes(const ProtocolTrialSettings& trial);

/// Checks, before anything is written there, that files can be written in `folder` now: access(2) for
/// writing, then a probe file created and removed (which also catches a read-only or immutable folder of a
/// privileged user), and at least `free_bytes` and 16 inodes free on its file system (statvfs). Throws
/// DataError naming the folder and the reason.
void check_writable_folder(const std::filesystem::path& folder, std::uintmax_t free_bytes);

/// Where each file of a session folder lives: the one definition its writer (SessionFolder) and every reader
/// (the report, the tidy tables, the series of sessions, a learning writer's memory) take paths from.
///   FOLDER/session.json            the manifest (the plan, the setup, the protocol's copy)
///   FOLDER/log.jsonl               the event log, locked while a run works on the session
///   FOLDER/trials/STEM.json        a saved trial's record (its existence marks the trial saved)
///   FOLDER/trials/STEM.trace.h5    its trace (HDF5, trace_hdf5.hpp); FOLDER/trials/STEM.svg its drawing
///   FOLDER/trials/attempts/        attempts that did not become the trial
///   FOLDER/teachers/               a replay condition's teachers
struct SessionLayout {
  [[nodiscard]] static std::filesystem::path manifest(const std::filesystem::path& folder);
  [[nodiscard]] static std::filesystem::path log(const std::filesystem::path& folder);
  [[nodiscard]] static std::filesystem::path trials(const std::filesystem::path& folder);
  [[nodiscard]] static std::filesystem::path attempts(const std::filesystem::path& folder);
  [[nodiscard]] static std::filesystem::path teachers(const std::filesystem::path& folder);
  /// FOLDER/trials/STEM.json of `trial` (SessionFolder::trial_stem).
  [[nodiscard]] static std::filesystem::path record(const std::filesystem::path& folder,
                                                    const PlannedTrial& trial);
};

/// A session folder, opened by one process at a time. Move-only; the lock is released on destruction.
class SessionFolder {
 public:
  /// Creates ROOT/SUBJECT/PROTOCOL-SUBJECT-YYYYMMDD-HHMMSS (UTC; a "-2", "-3" ... suffix when it exists;
  /// the name is the session id, unique across subjects), writes
  /// session.json with the plan of `plan_session` for `setup.session_number` and starts the log
  /// ("session_created"). A transfer choice of the protocol must be resolved (`resolve_transfer_choices`).
  /// Throws InvalidArgument for a bad setup (subject id, writer, profile, pacing, a session number the
  /// protocol does not have, `previous` missing for a later session or given for the first), DataError
  /// naming the path when a folder or file cannot be made, and as `check_session_manifest_size` (before
  /// any folder is made).
  static SessionFolder create(const std::filesystem::path& root, const SessionSetup& setup,
                              const LoadedProtocol& protocol,
                              const std::optional<PreviousSession>& previous = std::nullopt);
  /// Opens an existing session: reads session.json (the plan recorded there is the plan), checks the
  /// protocol copy against its SHA-256 and locks the log. Throws DataError naming the file when session.json
  /// cannot be read, InputError (a DataError) naming the file and JSON pointer for what its content holds
  /// that is refused, InputError naming `trials/`, `trials/attempts/` or `teachers/` when one is a symbolic
  /// link or not a folder, DataError naming a saved record the plan does not have
  /// (check_records_planned), StateError when another process has the session open.
  static SessionFolder open(const std::filesystem::path& folder);

  SessionFolder(SessionFolder&& other) noexcept;
  SessionFolder& operator=(SessionFolder&& other) noexcept;
  SessionFolder(const SessionFolder&) = delete;
  SessionFolder& operator=(const SessionFolder&) = delete;
  ~SessionFolder();

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  [[nodiscard]] const SessionManifest& manifest() const noexcept { return manifest_; }
  [[nodiscard]] const std::vector<PlannedTrial>& plan() const noexcept { return manifest_.plan; }

  /// "003-test-vision-r1-U5927": the file name of a trial without extension.
  [[nodiscard]] static std::string trial_stem(const PlannedTrial& trial);
  /// The extension of a saved trial's trace: the columnar HDF5 file of `trial_trace_hdf5` (trace_hdf5.hpp;
  /// h5py, MATLAB and R read it). A record's `files.trace` names it. Folders written before hold gzip CSV
  /// (`.csv.gz`) or plain `.csv` traces, named by `files.csv`, which readers still read.
  static constexpr std::string_view kTraceExtension = "trace.h5";
  /// trials/STEM.EXTENSION
  [[nodiscard]] std::filesystem::path trial_file(const PlannedTrial& trial, std::string_view extension) const;
  /// True when the trial's JSON exists.
  [[nodiscard]] bool is_saved(const PlannedTrial& trial) const;
  [[nodiscard]] std::size_t saved_count() const;
  /// The first planned trial not saved yet, or nullopt when every trial is saved.
  [[nodiscard]] std::optional<std::size_t> next_unsaved() const;

  /// Saves a finished trial: `trace` (the bytes of its trace file, `trial_trace_hdf5`, as STEM.trace.h5) and
  /// `svg` atomically, then `json` with link(2), so it never replaces a file. Throws StateError naming the
  /// file when the trial was saved already, DataError when a write fails.
  void save_trial(const PlannedTrial& trial, std::string_view json, std::string_view trace,
                  std::string_view svg);
  /// Keeps an attempt that did not become the saved trial (interrupted, failed) in trials/attempts/ as
  /// STEM.attempt-K.json and .trace.h5 (as save_trial's) with the first free K; `json` is made by
  /// `record(trace_file_name)`, so that the attempt's record names the trace kept beside it. Returns the
  /// JSON's path.
  std::filesystem::path save_attempt(const PlannedTrial& trial,
                                     const std::function<std::string(const std::string&)>& record,
                                     std::string_view trace);

  /// Checks every folder and file a run of the session writes (the session folder, trials/, trials/attempts/,
  /// teachers/, log.jsonl) with `check_writable_folder`, the free space for one trial's files
  /// (`trial_files_bytes` of the protocol). `run_session` calls it before its first trial. Throws DataError
  /// naming the folder or file.
  void check_writable() const;

  /// Checks that the saved records name this session by its id, the folder's name: a folder renamed since
  /// its first trial was saved is a DataError naming that record's /session, before a resume saves records
  /// under the new name beside those of the old one.
  void check_records_name_this_session() const;

  /// Appends {"time_utc": ..., "event": EVENT, ...details} as one line to log.jsonl and fsyncs it.
  /// `details_json` is a JSON object (its members are added) or empty. Throws InvalidArgument when it is
  /// not an object, DataError naming the log when the write or fsync fails.
  void log(std::string_view event, std::string_view details_json = {});

 private:
  SessionFolder(std::filesystem::path path, SessionManifest manifest, int log_fd);
  std::filesystem::path path_;
  SessionManifest manifest_;
  int log_fd_ = -1;
};

/// How a session folder's name begins while `SessionFolder::create` builds it (".partial.PID.HOST.NAME",
/// renamed to NAME once whole): a run killed before then leaves it. Readers skip it; the next `create` in the
/// subject's folder removes one whose process (on this host) is gone.
inline constexpr std::string_view kPartialSessionPrefix = ".partial.";
/// What a temporary session folder is, for messages naming one.
inline constexpr const char* kPartialNote =
    "a session folder left half made by a run killed before its first trial (its name begins \".partial.\"); "
    "no trial is in it: remove it (the next session run of the subject does)";
/// True when the folder's name marks it as being made (kPartialSessionPrefix).
[[nodiscard]] bool is_partial_session_folder(const std::filesystem::path& folder);

/// The session folders under `root`: `root` itself when it holds a session.json, else every folder below it
/// (at most 4 levels deep) that does, by path, digits as numbers (-2 before -10); temporary folders
/// (`is_partial_session_folder`) skipped. Throws DataError when `root` is not a folder or a temporary one.
[[nodiscard]] std::vector<std::filesystem::path> find_session_folders(const std::filesystem::path& root);

/// The trial record file `path` as `read_recorded_trial_file` reads it (trial/recorded_trial.hpp), and for a
/// study session's replay, which ran on the teacher kept in its session folder (trials/ is beside
/// teachers/), that file as its teacher (`spec.teacher`) bound by the SHA-256 the record gives
/// (/guidance/teacher) as `teacher_sha256`: `read_recorded_teacher` then refuses it, or a recording given
/// instead, when it is another file, naming it and both SHA-256. What `calligraphy trial --spec` and Python's
/// `rerun_trial` read. Throws what `read_recorded_trial_file` throws.
[[nodiscard]] RecordedTrial read_study_recorded_trial(const std::string& path);

}  // namespace calligraphy
