#pragma once
// The guidance of trials in `fading` and `replay` conditions, which depends on the session itself: the gain
// of a repetition follows the saved previous one, and a replay follows a teacher's recording kept in the
// session folder (docs/experiments.md, "Fading and replay conditions"). Internal.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/teacher_recording.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/session_runner.hpp"

namespace calligraphy::study_detail {

/// Seed of the skilled simulated writer who records a replay condition's teacher when the protocol names
/// none: fixed, so that every session of a protocol gets the same teacher.
inline constexpr std::uint64_t kRecordedTeacherSeed = 1;

/// A trial's guidance with its provenance.
struct PreparedGuidance {
  TrialGuidance guidance;
  // fading
  std::string previous_trial;  ///< file stem of the repetition the gain follows from; empty for the first
  double previous_gain = 0.0;
  nlohmann::json previous_deviation_mm;  ///< null when the previous repetition wrote no stroke
  // replay
  std::string teacher_file;    ///< relative to the session folder: "teachers/....json"
  std::string teacher_sha256;  ///< of the file's bytes
  std::string teacher_source;  ///< the protocol's path for the item, or "recorded"
  std::string teacher_writer;
  std::string teacher_characters;
};

/// The gain of `trial` in the fading `condition`: the condition's start gain for the first repetition of
/// the item, else `next_guidance_gain` from the gain and mean deviation recorded in the previous
/// repetition's saved JSON (so that a resumed session computes the same gain); 1 (full guidance) after a
/// repetition that wrote no stroke. Throws StateError when the previous repetition is not saved, DataError
/// when its record cannot be read.
PreparedGuidance fading_guidance(const SessionFolder& session, const StudyCondition& condition,
                                 const PlannedTrial& trial);

/// The teacher of `trial` in the replay `condition`: the copy in the session folder's teachers/ when there
/// is one; else the protocol's recording of the item (copied there), or one recorded there by a skilled
/// simulated writer (guided, lock-step, seed kRecordedTeacherSeed) on `scene`. Throws DataError for a
/// recording that cannot be read, InvalidArgument for one of other characters, StateError when the
/// simulated teacher does not write every stroke in order.
PreparedGuidance replay_guidance(SessionFolder& session, const StudyCondition& condition,
                                 const PlannedTrial& trial, const Scene& scene);

/// The record's "guidance" object: mode, gain and its origin (fading), teacher file, SHA-256, source and
/// characters (replay).
nlohmann::json guidance_record_json(const StudyCondition& condition, const PreparedGuidance& prepared);

}  // namespace calligraphy::study_detail
