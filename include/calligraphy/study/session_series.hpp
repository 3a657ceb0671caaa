#pragma once
/// \file session_series.hpp
/// A subject's sessions of one protocol across days: a protocol whose phases span sessions (a retention test
/// a day after training) is run as one session folder per session, each linked to the one before it
/// (session.json "previous_session"). This finds where a subject stands and links the next session.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/study/session_folder.hpp"

namespace calligraphy {

/// Where a subject stands in a protocol's series of sessions.
struct SessionSeries {
  int sessions = 1;  ///< the protocol's (StudyProtocol::session_count)
  /// The subject's session folders of this protocol (the same SHA-256), by session number (index 0: the
  /// first); each number's newest folder when a session was started twice.
  std::vector<std::filesystem::path> folders;
  int next = 1;  ///< the session to start next; `sessions + 1` when every session is complete
  /// A session with unsaved trials (resume it before the next starts); nullopt when none.
  std::optional<std::filesystem::path> unfinished;
  /// What links session `next` to the one before it (its `elapsed_s` measured now, its session.json's
  /// SHA-256, `delay` "waited" or not yet due); nullopt for the first session or when every session is
  /// complete.
  std::optional<PreviousSession> previous;
  /// The trial record whose end `previous->ended_utc` is (empty without `previous`).
  std::filesystem::path previous_record;
  /// True when session `next` may start now: the first, or the previous one's delay has passed.
  [[nodiscard]] bool due() const noexcept { return !previous || previous->elapsed_s >= previous->delay_s; }
  /// True when the previous session ended after now by this computer's clock (another clock, or a wrong one).
  [[nodiscard]] bool ended_in_future() const noexcept { return previous && previous->elapsed_s < 0.0; }
};

/// The series of `subject_id` under the study folder `root` (ROOT/SUBJECT/..., as SessionFolder::create
/// lays it out) for `protocol`, checked as a chain: each session after the first follows the folder of the
/// session before it by name and, where recorded, by its session.json's SHA-256. A missing subject folder is
/// a series not begun; a session with any planned trial unsaved is `unfinished`. Throws DataError naming the
/// file for a damaged session.json or trial record, a session of another subject in the folder (naming where
/// it belongs), a session missing before a later one (moved or deleted), or a link to another folder or
/// content than the session before it.
[[nodiscard]] SessionSeries session_series(const std::filesystem::path& root, const std::string& subject_id,
                                           const LoadedProtocol& protocol);

/// Refuses `protocol` when a session under the study folder `root` (any subject's) was run with another
/// protocol of the same name (another SHA-256: the file was edited): the series would start again beside
/// it, and every reader would pool the two as one design. Throws DataError naming the protocol's file, that
/// session's folder and both SHA-256; a session.json that cannot be read is left to the readers that need it.
void check_protocol_unchanged(const std::filesystem::path& root, const LoadedProtocol& protocol);

/// Refuses to resume `session` (one with unsaved trials) when a later session in its subject's folder
/// follows it: that session began from this one with every trial saved, so a record missing now was removed
/// since. Throws DataError naming the missing record and the later session's folder.
void check_not_followed(const SessionFolder& session);

/// An exclusive lock on one subject's series under `root` (flock(2) on the folder ROOT/SUBJECT), held by a
/// run from reading the series until its session is written, so that concurrent runs of one subject take
/// turns (the later sees what the earlier wrote) instead of starting a session twice. The system releases
/// it when the holder ends, however it ends.
class SeriesLock {
 public:
  /// Creates the subject's folder when missing and waits until the lock is free, calling `waiting` with the
  /// folder's path once when it is not free at first. While it waits it polls `should_stop` (every 50 ms):
  /// true ends the wait without the lock (`held()` false), so that a stop signal is not ignored behind
  /// another run. Throws DataError naming the folder when it cannot be created or locked.
  SeriesLock(const std::filesystem::path& root, const std::string& subject_id,
             const std::function<void(const std::filesystem::path&)>& waiting = {},
             const std::function<bool()>& should_stop = {});
  SeriesLock(const SeriesLock&) = delete;
  SeriesLock& operator=(const SeriesLock&) = delete;
  ~SeriesLock();

  /// True when the lock is held (false only when `should_stop` ended the wait).
  [[nodiscard]] bool held() const noexcept { return fd_ >= 0; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

/// An exclusive lock on a study folder for one run of `session run` (flock(2) on ROOT/.calligraphy-run.lock,
/// created when missing with ROOT), taken without waiting: a second run into the study folder while one runs
/// (the same protocol, or another file of the same name) is refused, so that no session is started twice.
/// While held, the lock file holds the holder's process id and command line, which the refusal names; a run
/// that ends empties it. The system
/// releases the lock when the holder ends, however it ends (a killed run leaves a file, not a lock).
class StudyRunLock {
 public:
  /// Throws StateError naming the folder and the run that holds it when another process holds the lock,
  /// DataError naming the folder when it cannot be created or locked. `command` is this run's command line.
  StudyRunLock(const std::filesystem::path& root, const std::string& command);
  StudyRunLock(const StudyRunLock&) = delete;
  StudyRunLock& operator=(const StudyRunLock&) = delete;
  ~StudyRunLock();

  /// The lock file's name in a study folder; readers skip it (not a folder).
  static constexpr const char* kFileName = ".calligraphy-run.lock";

 private:
  int fd_ = -1;
};

}  // namespace calligraphy
