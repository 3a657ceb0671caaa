#include "study/trial_guidance.hpp"

#include <cmath>
#include <cstdio>
#include <system_error>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/render/guidance_schedule.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "core/json_reader.hpp"
#include "study/names.hpp"
#include "study/record_metrics.hpp"
#include "study/saved_sessions.hpp"

namespace calligraphy::study_detail {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// "teachers/CONDITION-U5341_U4EBA.json" (relative to the session folder): one teacher per condition and item.
std::string teacher_file_name(const StudyCondition& condition, const std::u32string& characters) {
  std::string name = (SessionLayout::teachers({}) / (condition.name + "-")).string();
  for (std::size_t i = 0; i < characters.size(); ++i) {
    char code[16];
    std::snprintf(code, sizeof code, "%sU%04X", i == 0 ? "" : "_", static_cast<unsigned>(characters[i]));
    name += code;
  }
  return name + ".json";
}

// The teacher a skilled simulated writer records on `scene`: guided by the paper's fixture, lock-step.
std::string record_teacher(const SessionFolder& session, const Scene& scene,
                           const std::u32string& characters) {
  const ProtocolTrialSettings& settings = session.manifest().protocol.protocol.trial;
  TrialSpec teacher;
  teacher.characters = encode_utf8(characters);
  teacher.guidance = true;
  teacher.writer = TrialWriter::simulated;
  teacher.writer_profile = "skilled";
  teacher.seed = kRecordedTeacherSeed;
  teacher.rate_hz = settings.rate_hz;
  teacher.max_duration_s = settings.max_duration_s;
  teacher.pacing = TrialPacing::lock_step;
  // The simulated device, made here: the teacher's trial is the library's, on no device of the session's.
  SimulatedDevice device;
  const auto checked = Checked<TrialSpec>::check(teacher);
  SimulatedWriting writing(*checked);
  TrialRunInputs inputs;
  inputs.device = &device;
  inputs.hand_maker = &writing;
  const TrialResult result = run_whole_trial(build_whole_trial(checked, device.info()), scene, inputs).result;
  if (result.aborted || !result.metrics.completed_in_order) {
    throw StateError("the simulated teacher of \"" + encode_utf8(characters) + "\" wrote " +
                     std::to_string(result.metrics.strokes_completed) + " of " +
                     std::to_string(result.metrics.strokes_total) + " strokes in order (" +
                     to_string(result.end) + "): give the condition a teacher's recording of it");
  }
  return teacher_recording_json(teacher_recording_from_trace(encode_utf8(characters), "simulated skilled",
                                                             teacher.device, teacher.rate_hz, result.trace));
}

}  // namespace

const PlannedTrial* previous_repetition(const std::vector<PlannedTrial>& plan, const PlannedTrial& trial) {
  const PlannedTrial* previous = nullptr;
  for (const PlannedTrial& earlier : plan) {
    if (earlier.index >= trial.index) break;
    if (earlier.condition == trial.condition && earlier.characters == trial.characters) previous = &earlier;
  }
  return previous;
}

PreparedGuidance repetition_guidance(const StudyCondition& condition, const PlannedTrial* previous,
                                     const json* previous_record, const std::string& source) {
  PreparedGuidance prepared;
  if (!adapts_by_repetition(condition)) return prepared;
  // The one schedule (render/guidance_schedule.hpp), as the trainer and Python use it.
  const GuidanceSchedule& schedule = *condition.guidance->schedule;
  const bool fading = schedule.adapts == AdaptiveGuidance::fading;
  const bool assist = schedule.adapts == AdaptiveGuidance::assist_as_needed;
  const bool skill = schedule.adapts == AdaptiveGuidance::skill_adaptive;
  const RepetitionGuidance first = schedule.start();
  prepared.guidance.gain = first.gain;
  prepared.guidance.band_m = first.band_m;
  if (skill) prepared.guidance.mode = first.mode;
  if (!previous || !previous_record) return prepared;
  const json_detail::JsonView record(*previous_record, "", source);
  prepared.previous_trial = SessionFolder::trial_stem(*previous);
  if (!record.has("guidance"))
    json_detail::fail(source, "/guidance", "missing (required): no guidance to adapt from");
  const json_detail::JsonView guidance = record.object("guidance");
  if (fading) prepared.previous_gain = guidance.number("gain", 0.0, 1e6);
  if (assist) prepared.previous_band_m = guidance.number("band_m", 0.0, 1e6);
  if (!study_detail::contains_metric(record, "mean_deviation_m"))
    json_detail::fail(source, "/mean_deviation_m", "missing (required): no mean deviation to adapt from");
  // null when the repetition wrote nothing; a record older than the metric table gives it in mm
  const std::optional<double> deviation_m = study_detail::record_metric(record, "mean_deviation_m");
  prepared.previous_deviation_m = deviation_m ? json(*deviation_m) : json(nullptr);
  RepetitionGuidance before = first;
  before.gain = fading ? prepared.previous_gain : first.gain;
  before.band_m = assist ? prepared.previous_band_m : first.band_m;
  const RepetitionGuidance following = schedule.next(before, deviation_m);
  prepared.guidance.gain = following.gain;
  prepared.guidance.band_m = following.band_m;
  if (skill) prepared.guidance.mode = following.mode;
  return prepared;
}

PreparedGuidance repetition_guidance(const SessionFolder& session, const StudyCondition& condition,
                                     const PlannedTrial& trial) {
  const PlannedTrial* previous = previous_repetition(session.plan(), trial);
  if (!previous) return repetition_guidance(condition, nullptr, nullptr, "");
  const fs::path file = session.trial_file(*previous, "json");
  if (!session.is_saved(*previous)) {
    throw StateError("trial " + SessionFolder::trial_stem(trial) + ": its guidance follows " +
                     SessionFolder::trial_stem(*previous) + ", which is not saved");
  }
  const json record = study_detail::read_trial_record(file);
  return repetition_guidance(condition, previous, &record, file.string());
}

bool adapts_by_repetition(const StudyCondition& condition) noexcept {
  return condition.guidance && condition.guidance->schedule;
}

GuidanceLaw trial_guidance_law(const ConditionGuidance& condition, const TrialGuidance& guidance) {
  GuidanceLaw law = condition.law;
  if (condition.schedule) {
    RepetitionGuidance repetition = condition.schedule->start();
    repetition.gain = guidance.gain;
    repetition.band_m = guidance.band_m;
    if (guidance.mode) repetition.mode = *guidance.mode;
    law = condition.schedule->law_of(repetition, std::move(law));
  }
  if (auto* replay = std::get_if<ReplayGuidance>(&law)) replay->teacher_trajectory = guidance.teacher;
  return law;
}

namespace {

// A teacher's recording of `characters` in `text` read from `source`, for `condition` (whose teacher is
// named `teacher_source`): what the replay runs on, or an error naming both.
TeacherRecording checked_teacher(const std::string& text, const std::string& source,
                                 const StudyCondition& condition, const std::string& teacher_source,
                                 const std::u32string& characters) {
  TeacherRecording teacher = parse_teacher_recording(text, source);
  try {
    require_teacher_for(teacher, encode_utf8(characters));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("condition '" + condition.name + "', teacher " + teacher_source + ": " + e.what());
  }
  return teacher;
}

}  // namespace

PreparedGuidance replay_guidance(SessionFolder& session, const StudyCondition& condition,
                                 const PlannedTrial& trial, const Scene& scene) {
  PreparedGuidance prepared;
  prepared.teacher_file = teacher_file_name(condition, trial.characters);
  const fs::path path = session.path() / prepared.teacher_file;
  const auto given = condition.teachers.find(trial.characters);
  prepared.teacher_source = given == condition.teachers.end() ? "recorded" : given->second;
  const auto checked = [&](const std::string& text, const std::string& source) {
    return checked_teacher(text, source, condition, prepared.teacher_source, trial.characters);
  };
  std::error_code error;
  if (!fs::exists(path, error)) {
    std::string text;
    if (given == condition.teachers.end()) {
      text = record_teacher(session, scene, trial.characters);
    } else {
      const fs::path source = session.manifest().protocol.path.parent_path() / given->second;
      text = read_small_file(source, kMaxTeacherRecordingBytes, "teacher's recording");
      (void)checked(text, source.string());  // before it is copied
    }
    fs::create_directories(path.parent_path(), error);
    write_file_atomically(path, text);
    session.log("teacher_saved", json_text(json{{"condition", condition.name},
                                                {"characters", encode_utf8(trial.characters)},
                                                {"file", prepared.teacher_file},
                                                {"source", prepared.teacher_source},
                                                {"sha256", sha256_hex(text)}}));
  }
  // The session's own copy: read without following a link, as every file of a session folder.
  const std::string text = read_session_file(path, kMaxTeacherRecordingBytes, "teacher's recording");
  TeacherRecording teacher = checked(text, path.string());
  prepared.teacher_sha256 = sha256_hex(text);
  prepared.teacher_writer = teacher.writer;
  prepared.teacher_characters = teacher.characters;
  prepared.guidance.teacher = std::move(teacher.samples);
  prepared.guidance.teacher_file = prepared.teacher_file;
  return prepared;
}

json guidance_record_json(const StudyCondition& condition, const PreparedGuidance& prepared) {
  json guidance = {{"mode", to_string(condition_mode(condition))}};
  const GuidanceSchedule* schedule =
      condition.guidance && condition.guidance->schedule ? &*condition.guidance->schedule : nullptr;
  const bool fading = schedule && schedule->adapts == AdaptiveGuidance::fading;
  const bool assist = schedule && schedule->adapts == AdaptiveGuidance::assist_as_needed;
  if (fading) {
    guidance["gain"] = prepared.guidance.gain;
    guidance["start_gain"] = schedule->start_gain;
    guidance["forgetting_factor"] = schedule->fading_rule.forgetting_factor;
    guidance["error_gain_per_m"] = schedule->fading_rule.error_gain_per_m;
  } else if (assist) {
    guidance["band_m"] = prepared.guidance.band_m;
    guidance["start_band_m"] = schedule->start_band_m;
    guidance["target_error_m"] = schedule->assist_rule.target_error_m;
    guidance["band_rate"] = schedule->assist_rule.rate;
    guidance["min_band_m"] = schedule->assist_rule.min_band_m;
    guidance["max_band_m"] = schedule->assist_rule.max_band_m;
  } else if (schedule) {  // skill-adaptive
    guidance["selected_mode"] = to_string(prepared.guidance.mode.value_or(GuidanceMode::fixed));
    guidance["threshold_m"] = schedule->skill_rule.threshold_m;
  } else if (replays_teacher(condition)) {
    guidance["teacher"] = {
        {"file", prepared.teacher_file},
        {"sha256", prepared.teacher_sha256},
        {"source", prepared.teacher_source},
        {"writer", prepared.teacher_writer},
        {"characters", prepared.teacher_characters},
        {"seed", prepared.teacher_source == "recorded" ? json(kRecordedTeacherSeed) : json(nullptr)}};
  }
  if (schedule) {
    guidance["previous_trial"] =
        prepared.previous_trial.empty() ? json(nullptr) : json(prepared.previous_trial);
    if (!prepared.previous_trial.empty()) {
      if (fading) guidance["previous_gain"] = prepared.previous_gain;
      if (assist) guidance["previous_band_m"] = prepared.previous_band_m;
      guidance["previous_mean_deviation_m"] = prepared.previous_deviation_m;
    }
  }
  return guidance;
}

ForceLawParameters condition_force_law(const StudyCondition& condition, const TrialGuidance& guidance,
                                       ForceLawParameters force) {
  // The renderer judges strokes as the quiz does.
  if (condition.quiz) {
    force.acceptance = condition.quiz->acceptance;
    force.acceptance.hint_after_misses = condition.quiz->hint_after();
  }
  // The trial's law: the condition's, as its schedule sets it for this repetition, with the replay's teacher.
  if (condition.guidance && force.guidance) {
    force.guidance_law = trial_guidance_law(*condition.guidance, guidance);
    if (condition.guidance->stiffness_n_per_m)
      force.guidance_stiffness_n_per_m = *condition.guidance->stiffness_n_per_m;
  }
  return force;
}

Checked<WholeTrial> study_whole_trial(const StudyCondition& condition, const TrialGuidance& guidance,
                                      const Checked<TrialSpec>& spec, const DeviceInfo& device) {
  return build_whole_trial(
      spec, device, {.force_law = condition_force_law(condition, guidance, stated_force_law(*spec, device))});
}

}  // namespace calligraphy::study_detail

namespace calligraphy {

void check_protocol_teachers(const LoadedProtocol& protocol) {
  for (const StudyCondition& condition : protocol.protocol.conditions) {
    for (const auto& [characters, given] : condition.teachers) {
      const std::filesystem::path source = protocol.path.parent_path() / given;
      try {
        const std::string text =
            study_detail::read_small_file(source, kMaxTeacherRecordingBytes, "teacher's recording");
        (void)study_detail::checked_teacher(text, source.string(), condition, given, characters);
      } catch (const DataError& e) {
        // The file cannot be read or is no teacher's recording: the condition that names it, then the file.
        // (checked_teacher's InvalidArgument names the condition and the teacher already.)
        throw DataError("condition '" + condition.name + "': " + e.what());
      }
    }
  }
}

}  // namespace calligraphy
