#pragma once
// A simulated subject that learns (SessionSetup::writer_learning "two-state"): its memory (sim/
// writer_memory.hpp) rebuilt from the saved trial records of its sessions, and the profile it writes with.
// Internal.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/subject_traits.hpp"
#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy::study_detail {

/// The traits of `setup`'s subject (sim/subject_traits.hpp): drawn from its seed for a simulated subject with
/// individual differences, else not drawn (the profile itself).
SubjectTraits subject_traits(const SessionSetup& setup);

/// The profile `setup`'s simulated subject writes with before it learns anything: its profile with its
/// traits.
WriterProfile subject_profile(const SessionSetup& setup);

/// The writer settings that make the profile `setup`'s subject (`individual_profile_fields`); empty when its
/// traits are not drawn.
std::vector<WriterSetting> individual_parameters(const SessionSetup& setup);

/// One saved trial as practice with the subject's `rates`: the typical strokes of its scene, its characters,
/// and the shares of the correction its guidance took from the hand (the record's force law and writer
/// profile). Throws DataError naming `source` when the record lacks them.
void practise_record(WriterMemory& memory, const nlohmann::json& record, const std::string& source,
                     const TwoStateRates& rates);

/// The memory of `session`'s subject before its first unsaved trial: the sessions before it (by their
/// `previous_session` links, each followed by `consolidate`), then this session's saved trials in order.
WriterMemory remembered(const SessionFolder& session);

/// The typical stroke IDs of a scene, stroke by stroke.
std::vector<int> typical_ids(const Scene& scene);

/// The writer settings of the subject's own profile `own` learned to `memory`'s skill for a trial of
/// `characters` with strokes `ids` (learned_profile, towards the skilled profile).
std::vector<WriterSetting> learned_parameters(const WriterMemory& memory, const WriterProfile& own,
                                              const std::vector<int>& ids, const std::u32string& characters);

/// Makes `spec` the trial of a learning subject: appends its writer parameters `learned_parameters` for the
/// strokes of `scene` and `characters` (after the subject's own, so that they win). Returns the skills
/// before the trial.
WriterSkills learn_into(TrialSpec& spec, const WriterMemory& memory, const WriterProfile& own,
                        const Scene& scene, const std::u32string& characters);

}  // namespace calligraphy::study_detail
