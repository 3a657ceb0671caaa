#pragma once
// Saving the trainer's trials as they end (--session DIR): per trial a JSON document (the keys of
// `calligraphy trial --json` plus subject, character, condition, start time, library version and the
// servo loop's statistics), the CSV trace and the SVG drawing, each written atomically under a new name
// so that nothing saved earlier is ever overwritten.
#include <filesystem>
#include <string>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy::trainer {

/// What describes one trial besides its result.
struct TrialRecordInfo {
  TrialDescription description;  ///< characters (the one character), guidance, writer, device...
  std::string subject;           ///< subject id
  std::string condition;         ///< "vision+haptic" or "vision" (the paper's two modes, 7.1)
  std::string start_time_utc;    ///< ISO 8601, e.g. 2024-05-01T12:00:00Z
  std::string library_version;
};

/// The three files saved for a trial.
struct SavedTrial {
  std::filesystem::path json, csv, svg;
};

/// The JSON document of a trial (trial_json's keys and the record's).
std::string trial_record_json(const TrialRecordInfo& info, const TrialResult& result);

/// Saves the trial into `folder` (created when missing) as <subject>-<character>-<n>.{json,csv,svg} with
/// the least n >= 1 for which none of the three exists; the JSON name is claimed with O_EXCL first, so
/// two trainers saving into one folder never take the same name. Throws DataError naming the path.
SavedTrial save_trial(const std::filesystem::path& folder, const TrialRecordInfo& info, const Scene& scene,
                      const TrialResult& result);

/// The current time as ISO 8601 UTC.
std::string utc_now_iso8601();

/// Throws InvalidArgument unless `subject` is 1-64 characters of [A-Za-z0-9._-] not starting with '.'
/// (it becomes part of file names).
void check_subject_id(const std::string& subject);

}  // namespace calligraphy::trainer
