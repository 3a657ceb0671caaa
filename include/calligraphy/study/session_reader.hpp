#pragma once
/// \file session_reader.hpp
/// The one reader of saved sessions, for the per-trial pages (report/study_report_html.hpp) and the tidy
/// tables (study_tables.hpp): the session folders under given roots (session_folder.hpp), then one session's
/// saved trials at a time, each trial's JSON record and trace (`.csv.gz`, or a plain `.csv` of older
/// folders; read by the pen-trace reader, report/pen_trace_csv.hpp) read as it is needed and dropped after,
/// so memory holds one trial, not the study. Reading takes no lock, so a running session can be reported;
/// trials not saved yet are left out.
#include <filesystem>
#include <functional>
#include <vector>

#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/study_tables.hpp"

namespace calligraphy {

/// Largest trial trace read: 256 MiB of text (an hour at 1 kHz is about 300 MB; a study trial lasts
/// minutes), on disk and decompressed.
inline constexpr std::uintmax_t kMaxTrialCsvBytes = std::uintmax_t{256} << 20;

/// One session to report: what the index and its page show, and what its trials are read by.
struct ReportedSession {
  ReportSession shown;
  std::filesystem::path folder;
  SessionManifest manifest;
};

/// The sessions under some roots.
struct StudyReportSessions {
  StudyReportIndex index;                 ///< the title, every session, notes (what simulated subjects were)
  std::vector<ReportedSession> sessions;  ///< sorted by path, as `index.sessions`
};

/// Every session under `roots` (each a session folder or a folder holding some), its manifest read and its
/// saved trials counted; no trial is read. Throws DataError naming the file (and JSON pointer) for a root
/// that is not a folder, no session found, a damaged session.json, and for one subject's session of one
/// protocol found twice (two folders of its session 1: the session was run twice; the message names the
/// subject and both folders), whose trials would otherwise be pooled as one session (the trainer's free
/// practice, a session 1 on every run, excepted).
[[nodiscard]] StudyReportSessions list_report_sessions(const std::vector<std::filesystem::path>& roots);

/// Calls `trial` with each saved trial of `session` in planned order, its record and trace read just
/// before and dropped after. With `rows`, also appends each trial's rows of the tidy tables to it, from the
/// same read of its record: the rows `read_study_tables` gives for this session. Throws DataError naming
/// the file (and JSON pointer or trace line) for a damaged trial record or trace (a record naming a trace
/// that cannot be read is at fault).
void read_session_trials(const ReportedSession& session, const std::function<void(const ReportTrial&)>& trial,
                         StudyTables* rows = nullptr);

/// Appends the rows of the tidy tables of each saved trial of `session` to `rows`, in planned order, from its
/// record alone (the trace is not read; a row names it). Throws DataError naming the file and JSON pointer
/// for a damaged trial record.
void read_session_rows(const ReportedSession& session, StudyTables& rows);

}  // namespace calligraphy
