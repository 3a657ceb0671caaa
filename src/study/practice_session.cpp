#include "calligraphy/study/practice_session.hpp"

#include <nlohmann/json.hpp>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/quiz_trace.hpp"
#include "study/trial_record.hpp"

namespace calligraphy {
namespace {

// The quiz condition's options as a protocol gives them: the hint's override only when there is one (the
// acceptance's otherwise).
nlohmann::json practice_quiz_json(const QuizOptions& quiz) {
  nlohmann::json out = {{"acceptance", study_detail::acceptance_json(quiz.acceptance)}};
  if (quiz.hint_after_misses) out["hint_after_misses"] = *quiz.hint_after_misses;
  out["accept_backwards"] = quiz.accept_backwards;
  return out;
}

// The "train" protocol: the row once under the first condition; the other conditions are defined so that
// the trials the window runs under them name a condition of the session's own protocol.
LoadedProtocol practice_protocol(const PracticeSetup& setup) {
  nlohmann::json items = nlohmann::json::array();
  for (const char32_t c : decode_utf8(setup.characters_utf8)) items.push_back(encode_utf8(c));
  const nlohmann::json protocol = {
      {"format", "calligraphy-study-protocol"},
      {"version", 1},
      {"name", "train"},
      {"description", "free practice in the trainer window (calligraphy train); the trials are those run"},
      {"conditions",
       {{{"name", kHapticCondition}, {"mode", "haptic"}},
        {{"name", kVisionCondition}, {"mode", "vision"}},
        {{"name", kQuizCondition}, {"mode", "quiz"}, {"quiz", practice_quiz_json(setup.quiz)}},
        {{"name", kFadingCondition}, {"mode", "fading"}},
        {{"name", kReplayCondition}, {"mode", "replay"}},
        {{"name", kAssistCondition}, {"mode", "assist-as-needed"}},
        {{"name", kAmplificationCondition}, {"mode", "error-amplification"}},
        {{"name", kTimingCondition}, {"mode", "timing"}}}},
      {"test", {{"characters", items}, {"conditions", {setup.first_condition}}, {"repetitions", 1}}}};
  return protocol_from_text(json_text(protocol, 2) + "\n", "calligraphy-train");
}

SessionFolder create_folder(const PracticeSetup& setup) {
  SessionSetup session;
  session.subject = {setup.subject, trailing_number(setup.subject)};
  session.device = setup.device;
  session.writer = setup.simulated_writer ? TrialWriter::simulated : TrialWriter::person;
  session.writer_profile = setup.writer_profile;
  session.writer_seed = setup.writer_seed;
  session.pacing = TrialPacing::real_time;
  return SessionFolder::create(setup.root, session, practice_protocol(setup));
}

}  // namespace

PracticeSession::PracticeSession(const PracticeSetup& setup) : setup_(setup), folder_(create_folder(setup)) {
  folder_.log("session_started", R"({"mode":"practice"})");
}

std::pair<std::filesystem::path, bool> PracticeSession::save(const PracticeTrial& trial,
                                                             const TrialResult& result) {
  PlannedTrial planned;
  planned.index = trials_++;
  planned.phase = StudyPhase::test;
  planned.condition = trial.condition;
  planned.characters = std::u32string(1, trial.character);
  planned.item = trial.item;
  planned.repetition = ++repetitions_[{trial.item, trial.condition}];

  const SessionManifest& manifest = folder_.manifest();
  const StudyCondition& condition = manifest.protocol.protocol.condition(trial.condition);
  study_detail::TrialRecordContext context;
  context.session = &manifest;
  context.trial = &planned;
  context.condition = &condition;
  context.options = trial.options;
  context.spec = trial.spec;
  context.device_name = setup_.device;
  context.device_info = setup_.device_info;
  context.hardware = setup_.hardware;
  context.simulated_writer = setup_.simulated_writer;
  context.simulation = trial.simulation;
  context.start_utc = trial.start_utc;
  context.end_utc = trial.end_utc;
  context.wall_time_s = trial.wall_time_s;
  const std::string stem = SessionFolder::trial_stem(planned);
  context.trace_file = stem + "." + std::string(SessionFolder::kTraceExtension);
  context.svg_file = stem + ".svg";
  const Scene& scene = *trial.scene;
  const WritingMetrics writing = trial_writing_metrics(scene, result, trial.options->force.acceptance);
  std::vector<std::vector<QuizEvent>> quiz;
  if (condition.quiz) quiz = quiz_characters(scene, result.trace, *condition.quiz);
  const bool keep_as_trial = result.end == TrialEnd::completed || result.end == TrialEnd::time_limit ||
                             result.end == TrialEnd::gave_up || result.end == TrialEnd::writer_finished;
  nlohmann::json details = {{"trial", planned.index + 1},
                            {"condition", planned.condition},
                            {"characters", encode_utf8(trial.character)},
                            {"file", stem},
                            {"end_reason", to_string(result.end)}};
  // The trace's bytes first: the record names them by their SHA-256.
  const std::string trace = trial_trace_hdf5(result.trace);
  context.trace_sha256 = sha256_hex(trace);
  if (keep_as_trial) {
    const std::string record =
        study_detail::trial_record_json(context, scene, result, writing, quiz.empty() ? nullptr : &quiz);
    folder_.save_trial(planned, record, trace, trial_svg(scene, result));
    folder_.log("trial_saved", json_text(details));
    return {folder_.trial_file(planned, "json"), true};
  }
  context.svg_file.clear();
  const auto record = [&](const std::string& trace_file) {
    context.trace_file = trace_file;  // the attempt's own, beside its record
    return study_detail::trial_record_json(context, scene, result, writing, quiz.empty() ? nullptr : &quiz);
  };
  const std::filesystem::path kept = folder_.save_attempt(planned, record, trace);
  details["abort_reason"] = result.abort_reason;
  folder_.log(result.end == TrialEnd::interrupted ? "trial_interrupted" : "trial_failed", json_text(details));
  return {kept, false};
}

void PracticeSession::log_stop(const std::string& reason) {
  folder_.log("session_stopped", nlohmann::json{{"reason", reason}, {"trials", trials_}}.dump());
}

}  // namespace calligraphy
