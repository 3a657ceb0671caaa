#pragma once
// The guidance of trials in conditions whose guidance depends on the session itself: the gain, band or mode
// of a repetition follows the saved previous one (fading, assist-as-needed, skill-adaptive), and a replay
// follows a teacher's recording kept in the session folder (docs/experiments.md, "Fading and replay
// conditions"). Internal.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "calligraphy/trial/whole_trial.hpp"

namespace calligraphy::study_detail {

/// Seed of the skilled simulated writer who records a replay condition's teacher when the protocol names
/// none: fixed, so that every session of a protocol gets the same teacher.
inline constexpr std::uint64_t kRecordedTeacherSeed = 1;

/// A trial's guidance with its provenance.
struct PreparedGuidance {
  TrialGuidance guidance;
  // fading, assist-as-needed, skill-adaptive
  std::string previous_trial;  ///< file stem of the repetition the guidance follows from; empty for the first
  double previous_gain = 0.0;  ///< fading
  double previous_band_m = 0.0;         ///< assist-as-needed
  nlohmann::json previous_deviation_m;  ///< [m]; null when the previous repetition wrote no stroke
  // replay
  std::string teacher_file;    ///< relative to the session folder: "teachers/....json"
  std::string teacher_sha256;  ///< of the file's bytes
  std::string teacher_source;  ///< the protocol's path for the item, or "recorded"
  std::string teacher_writer;
  std::string teacher_characters;
};

/// The guidance of `trial` in a condition that adapts repetition by repetition (`adapts_by_repetition`):
/// for the first repetition of the item, the condition's start (gain, band; fixed guidance for skill-
/// adaptive); for a later one, from the guidance and mean deviation recorded in the previous repetition's
/// saved JSON (so that a resumed session computes the same): `next_guidance_gain` (fading),
/// `next_assist_band` (assist-as-needed), `skill_adaptive_mode` (skill-adaptive). After a repetition that
/// wrote no stroke: full guidance (gain 1, the narrowest band, fixed guidance). Throws StateError when the
/// previous repetition is not saved, DataError when its record cannot be read.
PreparedGuidance repetition_guidance(const SessionFolder& session, const StudyCondition& condition,
                                     const PlannedTrial& trial);

/// The repetition whose guidance `trial` follows: the last trial of `plan` before it with the same condition
/// and characters; nullptr for the first.
const PlannedTrial* previous_repetition(const std::vector<PlannedTrial>& plan, const PlannedTrial& trial);

/// `repetition_guidance` from the previous repetition and its record, held by the caller (a simulated cohort
/// keeps them in memory): the condition's start when `previous` or `previous_record` is nullptr. Throws
/// DataError naming `source` when the record lacks the guidance or the deviation.
PreparedGuidance repetition_guidance(const StudyCondition& condition, const PlannedTrial* previous,
                                     const nlohmann::json* previous_record, const std::string& source);

/// The force law of a trial of `condition`: `force` (made from the trial's specification, fitted to the
/// device) with what the condition sets beyond the specification: the quiz's acceptance, the guidance law
/// (`trial_guidance_law`: the replay's teacher and lead, the repulsive field's bound, ...), a guidance
/// stiffness of its own. The part `study_whole_trial` gives the builder.
[[nodiscard]] ForceLawParameters condition_force_law(const StudyCondition& condition,
                                                     const TrialGuidance& guidance, ForceLawParameters force);

/// The whole trial of a planned study trial, the one function that makes it for sessions, cohorts and the
/// plan's check: its checked specification `spec` (`study_trial_spec`, checked with
/// `study_teacher_source(condition)`) with the force law of `condition` for the repetition's `guidance`
/// (`condition_force_law` over the force law the specification states on the device of figures `device`),
/// through the one builder (`build_whole_trial`), which checks it once. A replay's teacher samples
/// (`guidance.teacher`) are the runner's input (TrialRunInputs::teacher), not part of it. Throws
/// InvalidArgument naming the part at fault.
[[nodiscard]] Checked<WholeTrial> study_whole_trial(const StudyCondition& condition,
                                                    const TrialGuidance& guidance,
                                                    const Checked<TrialSpec>& spec, const DeviceInfo& device);

/// Whether `condition`'s guidance follows the previous repetition of the item: it has a schedule (fading,
/// assist-as-needed, skill-adaptive).
[[nodiscard]] bool adapts_by_repetition(const StudyCondition& condition) noexcept;

/// The guidance law of a trial of a condition with `condition`'s guidance: its law as its schedule sets it
/// for the repetition `guidance` gives (its gain, band or skill-adaptive's mode), a replay with `guidance`'s
/// teacher.
[[nodiscard]] GuidanceLaw trial_guidance_law(const ConditionGuidance& condition,
                                             const TrialGuidance& guidance);

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
