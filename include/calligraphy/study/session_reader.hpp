#pragma once
/// \file session_reader.hpp
/// Reads saved sessions back: the folders under given roots (session_folder.hpp), each saved trial's
/// JSON record and CSV trace, into the model of the study report page (report/study_report_html.hpp).
/// Reading takes no lock, so a running session can be reported; trials not saved yet are left out.
#include <filesystem>
#include <vector>

#include "calligraphy/report/study_report_html.hpp"

namespace calligraphy {

/// Largest trial CSV read: 256 MiB (an hour at 1 kHz is about 300 MB; a study trial lasts minutes).
inline constexpr std::uintmax_t kMaxTrialCsvBytes = std::uintmax_t{256} << 20;

/// The report of every session under `roots` (each a session folder or a folder holding some): sessions
/// sorted by path, trials in planned order. Conditions and test characters come from the first session's
/// protocol; a note says when sessions ran under different protocols. Throws DataError naming the file
/// (and JSON pointer or CSV line) for a root that is not a folder, no session found, a damaged
/// session.json, trial record or trace.
[[nodiscard]] StudyReport read_study_report(const std::vector<std::filesystem::path>& roots);

}  // namespace calligraphy
