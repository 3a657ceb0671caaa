#include "calligraphy/study/cohort.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/worker_threads.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/legibility/legibility.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/trial/quiz_trace.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "study/names.hpp"
#include "study/remembered_writer.hpp"
#include "study/trial_guidance.hpp"
#include "study/trial_record.hpp"
#include "study/trial_row.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;

// The device every simulated subject writes on: the registry's simulated Phantom (SimulatedDevice with its
// default parameters), by the name session run records.
constexpr const char* kCohortDevice = "simulated";

// The manifest a session folder of this subject's session `number` would hold, without its folder.
SessionManifest cohort_manifest(const LoadedProtocol& protocol, const SubjectAssignment& subject,
                                const CohortSetup& setup, int number) {
  SessionManifest manifest;
  // A key across subjects, as a session folder's name is: the protocol, the subject, the session number.
  manifest.session_id = protocol.protocol.name + "-" + subject.id + "-s" + std::to_string(number);
  manifest.setup.subject = subject;
  manifest.setup.device = kCohortDevice;
  manifest.setup.writer = TrialWriter::simulated;
  manifest.setup.writer_profile = setup.writer_profile;
  manifest.setup.writer_seed = subject_seed(subject.id);
  manifest.setup.writer_learning = setup.writer_learning;
  manifest.setup.individual_differences = setup.individual_differences;
  manifest.setup.pacing = TrialPacing::lock_step;
  manifest.setup.session_number = number;
  manifest.protocol = protocol;
  manifest.plan = plan_session(protocol.protocol, subject, number);
  manifest.group = subject_group(protocol.protocol, subject);
  return manifest;
}

// A replay's teacher is recorded into its session folder, which a cohort does not have.
void refuse_replay(const StudyProtocol& protocol) {
  for (const StudyCondition& condition : protocol.conditions) {
    if (replays_teacher(condition)) {
      throw InvalidArgument("condition '" + condition.name +
                            "': a replay's teacher is kept in a session folder; a simulated cohort runs "
                            "without one (run it with calligraphy session run)");
    }
  }
}

// One trial as a session folder would save it: its record (trial_record.hpp), kept in memory.
json cohort_trial_record(const SessionManifest& manifest, const PlannedTrial& trial,
                         const StudyCondition& condition, const Scene& scene, WriterMemory& memory,
                         const json* previous_record, const std::function<bool()>& should_stop) {
  const std::string source = manifest.setup.subject.id + ", session " +
                             std::to_string(manifest.setup.session_number) + ", trial " +
                             std::to_string(trial.index + 1);
  study_detail::PreparedGuidance guidance;
  if (study_detail::adapts_by_repetition(condition)) {
    const PlannedTrial* previous = study_detail::previous_repetition(manifest.plan, trial);
    guidance = study_detail::repetition_guidance(condition, previous, previous_record, source);
  }
  TrialSpec spec = study_trial_spec(manifest, condition, trial, guidance.guidance);
  const bool learning = manifest.setup.writer_learning == WriterLearning::two_state;
  std::optional<WriterSkills> skills;
  if (learning)
    skills = study_detail::learn_into(spec, memory, study_detail::subject_profile(manifest.setup), scene,
                                      trial.characters);
  // The registry's simulated device, made here: asking the registry would scan every hardware backend (USB)
  // for each trial, from every thread at once.
  const auto device = std::make_unique<SimulatedDevice>();
  TrialRunInputs inputs;
  inputs.device = device.get();
  inputs.should_stop = should_stop;
  const auto checked = Checked<TrialSpec>::check(std::move(spec), study_teacher_source(condition));
  const Checked<WholeTrial> whole =
      study_detail::study_whole_trial(condition, guidance.guidance, checked, device->info());
  SimulatedWriting writing(*checked);
  inputs.hand_maker = &writing;
  const auto wall_start = std::chrono::steady_clock::now();
  const TrialRun run = run_whole_trial(whole, scene, inputs);
  const TrialResult& result = run.result;
  if (result.end != TrialEnd::completed && result.end != TrialEnd::time_limit &&
      result.end != TrialEnd::gave_up && result.end != TrialEnd::writer_finished) {
    throw StateError(source + ": the trial ended " + std::string(to_string(result.end)) + " (" +
                     result.abort_reason + ") and was not kept");
  }
  study_detail::TrialRecordContext context;
  context.session = &manifest;
  context.trial = &trial;
  context.condition = &condition;
  context.device_name = manifest.setup.device;
  context.device_info = run.device;
  context.simulated_writer = true;
  context.guidance = study_detail::guidance_record_json(condition, guidance);
  context.writer_skills = skills;
  context.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  context.options = &run.options;
  context.spec = &*checked;
  context.simulation.writer = writing.profile();
  context.simulation.seed = checked->seed;
  context.writer_log = writing.log();
  std::vector<std::vector<QuizEvent>> quiz;
  if (condition.quiz) quiz = quiz_characters(scene, result.trace, *condition.quiz);
  json record =
      study_detail::trial_record(context, scene, result, run.metrics, quiz.empty() ? nullptr : &quiz);
  // Learned from as a session learns from its saved record.
  if (learning)
    study_detail::practise_record(memory, record, source,
                                  study_detail::subject_traits(manifest.setup).learning);
  return record;
}

}  // namespace

void CohortSetup::validate() const {
  try {
    (void)calligraphy::writer_profile(writer_profile);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("CohortSetup.writer_profile: ") + e.what());
  }
  if (enum_spelling(writer_learning) == "?") {  // a value cast from outside the table
    throw InvalidArgument("CohortSetup.writer_learning: expected " +
                          join_spellings(enum_spellings<WriterLearning>(), " or ", "'"));
  }
}

std::vector<SubjectAssignment> numbered_subjects(std::size_t count, const std::string& prefix) {
  if (count == 0 || count > kMaxCohortSubjects) {
    throw InvalidArgument("numbered_subjects: a cohort has 1 to " + std::to_string(kMaxCohortSubjects) +
                          " subjects, got " + std::to_string(count));
  }
  std::vector<SubjectAssignment> subjects;
  subjects.reserve(count);
  for (std::size_t k = 1; k <= count; ++k) {
    char number[32];
    std::snprintf(number, sizeof number, "%02zu", k);
    SubjectAssignment subject{prefix + number, k};
    if (!study_detail::is_label(subject.id, 64)) {
      throw InvalidArgument("subject prefix '" + prefix + "': '" + subject.id +
                            "' is not a subject id (1-64 of A-Z a-z 0-9 _ -)");
    }
    subjects.push_back(std::move(subject));
  }
  return subjects;
}

StudyTables simulate_subject(const LoadedProtocol& protocol, const SubjectAssignment& subject,
                             const CohortSetup& setup) {
  setup.validate();
  refuse_replay(protocol.protocol);
  const CharacterLibrary standard = CharacterLibrary::standard();
  std::map<char32_t, Character> characters;  // fitted once per subject
  const auto character = [&](char32_t code_point) -> const Character& {
    auto found = characters.find(code_point);
    if (found == characters.end()) {
      Character model = setup.load_character ? setup.load_character(code_point) : standard.load(code_point);
      found = characters.emplace(code_point, std::move(model)).first;
    }
    return found->second;
  };
  StudyTables tables;
  WriterMemory memory;
  for (int number = 1; number <= protocol.protocol.session_count(); ++number) {
    if (number > 1) consolidate(memory);  // hours or days between the sessions
    const SessionManifest manifest = cohort_manifest(protocol, subject, setup, number);
    std::vector<json> records(manifest.plan.size());
    for (const PlannedTrial& trial : manifest.plan) {
      const StudyCondition& condition = protocol.protocol.condition(trial.condition);
      std::vector<Character> models;
      for (const char32_t c : trial.characters) models.push_back(character(c));
      const Scene scene = Scene::lay_out(models);
      const PlannedTrial* previous = study_detail::previous_repetition(manifest.plan, trial);
      records[trial.index] =
          cohort_trial_record(manifest, trial, condition, scene, memory,
                              previous ? &records[previous->index] : nullptr, setup.should_stop);
      tables.trials.push_back(study_detail::trial_row(records[trial.index], manifest.setup.subject.id,
                                                      manifest, trial, tables.strokes));
    }
  }
  return tables;
}

StudyTables simulate_cohort(const LoadedProtocol& protocol, const std::vector<SubjectAssignment>& subjects,
                            const CohortSetup& setup, unsigned threads,
                            const std::function<void(std::size_t)>& progress) {
  if (threads == 0) throw InvalidArgument("simulate_cohort: threads must be at least 1");
  if (subjects.size() > kMaxCohortSubjects) {
    throw InvalidArgument("simulate_cohort: a cohort has at most " + std::to_string(kMaxCohortSubjects) +
                          " subjects, got " + std::to_string(subjects.size()));
  }
  setup.validate();
  refuse_replay(protocol.protocol);
  // Every character of every subject's plan, loaded here once: the workers only read the map.
  const CharacterLibrary standard = CharacterLibrary::standard();
  std::map<char32_t, Character> characters;
  for (const SubjectAssignment& subject : subjects) {
    for (int number = 1; number <= protocol.protocol.session_count(); ++number) {
      for (const PlannedTrial& trial : plan_session(protocol.protocol, subject, number)) {
        for (const char32_t c : trial.characters) {
          if (characters.count(c) == 0)
            characters.emplace(c, setup.load_character ? setup.load_character(c) : standard.load(c));
        }
      }
    }
  }
  CohortSetup shared = setup;
  shared.load_character = [&characters](char32_t c) { return characters.at(c); };

  // The recogniser of every trial's legibility opens its model (some 27 MB) once, on first use: here, before
  // the threads map their stacks. Opened by the first thread after up to 1,024 stacks had used up an
  // address-space limit, zinnia's failing allocation ended the process instead of being caught.
  (void)legibility_available();
  std::vector<StudyTables> per_subject(subjects.size());
  std::mutex progress_mutex;  // one progress call at a time
  std::size_t done = 0;
  for_each_item(subjects.size(), threads, [&](std::size_t i) {
    per_subject[i] = simulate_subject(protocol, subjects[i], shared);
    const std::lock_guard<std::mutex> lock(progress_mutex);
    ++done;
    if (progress) progress(done);
  });

  StudyTables tables;
  for (StudyTables& subject : per_subject) {
    tables.trials.insert(tables.trials.end(), std::make_move_iterator(subject.trials.begin()),
                         std::make_move_iterator(subject.trials.end()));
    tables.strokes.insert(tables.strokes.end(), std::make_move_iterator(subject.strokes.begin()),
                          std::make_move_iterator(subject.strokes.end()));
  }
  return tables;
}

}  // namespace calligraphy
