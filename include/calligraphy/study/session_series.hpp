#pragma once
/// \file session_series.hpp
/// A subject's sessions of one protocol across days: a protocol whose phases span sessions (a retention test
/// a day after training) is run as one session folder per session, each linked to the one before it
/// (session.json "previous_session"). This finds where a subject stands and links the next session.
#include <filesystem>
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
  /// What links session `next` to the one before it (its `elapsed_s` measured now and `delay` "waited"
  /// or not yet due); nullopt for the first session or when every session is complete.
  std::optional<PreviousSession> previous;
  /// True when session `next` may start now: the first, or the previous one's delay has passed.
  [[nodiscard]] bool due() const noexcept { return !previous || previous->elapsed_s >= previous->delay_s; }
};

/// The series of `subject_id` under the study folder `root` (ROOT/SUBJECT/..., as SessionFolder::create
/// lays it out) for `protocol`. A missing subject folder is a series not begun. Throws DataError naming the
/// file for a damaged session.json or trial record.
[[nodiscard]] SessionSeries session_series(const std::filesystem::path& root, const std::string& subject_id,
                                           const LoadedProtocol& protocol);

}  // namespace calligraphy
