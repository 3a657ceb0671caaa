#include "calligraphy/study/session_runner.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/quiz_trace.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "study/names.hpp"
#include "study/remembered_writer.hpp"
#include "study/saved_sessions.hpp"
#include "study/trial_guidance.hpp"
#include "study/trial_record.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;

bool stop_requested(const SessionRunOptions& options) { return options.should_stop && options.should_stop(); }

// Why the run was asked to stop (SessionRunOptions::stop_reason), or "interrupted".
std::string stop_reason(const SessionRunOptions& options) {
  std::string reason = options.stop_reason ? options.stop_reason() : std::string();
  return reason.empty() ? "interrupted" : reason;
}

// The registry's listing of the session's device (whether a person moves it, what it can do).
// Refuses, before any trial runs, a plan this build or this device cannot carry out.
void check_plan(const SessionManifest& session, const DeviceListing& device) {
  for (const PlannedTrial& trial : session.plan) {
    const StudyCondition& condition = session.protocol.protocol.condition(trial.condition);
    // A replay's teacher is read (or recorded) when its trial comes; every other setting is checked now.
    if (replays_teacher(condition)) continue;
    (void)study_trial_options(session, condition, trial);
  }
  if (session.setup.writer == TrialWriter::simulated && device.capabilities.hardware) {
    throw InvalidArgument("device '" + device.name +
                          "' is moved by a person: a simulated writer cannot write on it (writer 'person')");
  }
}

json trial_details(const PlannedTrial& trial) {
  return {{"trial", trial.index + 1},       {"phase", to_string(trial.phase)},
          {"condition", trial.condition},   {"characters", encode_utf8(trial.characters)},
          {"repetition", trial.repetition}, {"file", SessionFolder::trial_stem(trial)}};
}

// The events of the session's log, in order; a line torn by a crash names nothing and is left out.
std::vector<json> logged_events(const SessionFolder& session) {
  const std::filesystem::path log_path = SessionLayout::log(session.path());
  const std::string text =
      study_detail::read_session_file(log_path, std::uintmax_t{256} << 20, "session log");
  std::vector<json> events;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    try {
      json line = json::parse(text.begin() + static_cast<std::ptrdiff_t>(begin),
                              text.begin() + static_cast<std::ptrdiff_t>(end));
      if (line.is_object()) events.push_back(std::move(line));
    } catch (const json::exception&) {
      // a line torn by a crash: it names nothing
    }
    begin = end + 1;
  }
  return events;
}

// Trials saved by a run that crashed before it could log them get their "trial_saved" line now, marked
// recovered, with what their record says (end_reason, time_s) as a trial_saved line has, so that the log
// names every saved trial once. `events` are the log's (logged_events).
void log_unlogged_saves(SessionFolder& session, const std::vector<json>& events) {
  std::set<std::string> logged;
  for (const json& event : events) {
    if (event.value("event", "") == "trial_saved") logged.insert(event.value("file", ""));
  }
  for (const PlannedTrial& trial : session.plan()) {
    if (!session.is_saved(trial) || logged.count(SessionFolder::trial_stem(trial)) > 0) continue;
    const json record = study_detail::read_trial_record(session.trial_file(trial, "json"));
    json details = trial_details(trial);
    details["end_reason"] = record.at("end_reason");
    details["time_s"] = record.at("total_time_s");
    details["recovered"] = true;
    session.log("trial_saved", json_text(details));
  }
}

}  // namespace

void SessionHost::before_trial(const PlannedTrial&, std::size_t) {}
void SessionHost::rest(double, const PlannedTrial&, const std::function<bool()>&) {}
void SessionHost::after_trial(const PlannedTrial&, const TrialOutcome&) {}
DisplayChannel* SessionHost::display_for(const PlannedTrial&, const StrokeAcceptance&) { return nullptr; }

TrialSpec study_trial_spec(const SessionManifest& session, const StudyCondition& condition,
                           const PlannedTrial& trial, const TrialGuidance& guidance) {
  TrialSpec spec;
  for (const char32_t c : trial.characters) spec.characters += encode_utf8(c);
  spec.device = session.setup.device;
  spec.guidance = condition.guidance.has_value();
  if (condition.guidance) {
    // The trial's law (the condition's, as its schedule sets it for this repetition) in the specification's
    // fields; a replay's teacher is the runner's (TrialRunInputs::teacher, from the session folder's copy
    // teachers/...), named by the record under "guidance".
    const GuidanceLaw law = study_detail::trial_guidance_law(*condition.guidance, guidance);
    spec.guidance_mode = mode_of(law);
    std::visit(
        [&](const auto& taken) {
          using Law = std::decay_t<decltype(taken)>;
          if constexpr (std::is_same_v<Law, FadingGuidance>) {
            try {
              check_parameter(&FadingGuidance::gain, taken.gain);  // the law's own table: one range
            } catch (const InvalidArgument& e) {
              throw InvalidArgument("condition '" + condition.name + "': " + e.what());
            }
            spec.guidance_gain = taken.gain;
          } else if constexpr (std::is_same_v<Law, ReplayGuidance>) {
            if (taken.teacher_trajectory.size() < 2) {
              throw InvalidArgument("condition '" + condition.name +
                                    "': a replay needs the teacher's recording");
            }
          } else if constexpr (std::is_same_v<Law, AssistAsNeededGuidance>) {
            spec.assist_band_m = taken.band_m;
          } else if constexpr (std::is_same_v<Law, ErrorAmplificationGuidance>) {
            spec.amplification_gain = taken.gain;
          } else if constexpr (std::is_same_v<Law, TimingGuidance>) {
            spec.timing_speed_m_s = taken.speed_m_s;
          }
        },
        law);
  }
  const bool simulated = session.setup.writer == TrialWriter::simulated;
  spec.writer = session.setup.writer;
  if (simulated) {
    spec.writer_profile = session.setup.writer_profile;
    // The subject's own baseline skill and motor noise (its traits); a learning subject's learned fields
    // are appended after these.
    spec.writer_parameters = study_detail::individual_parameters(session.setup);
  }
  // A seed of the simulated subject's own per trial, and per session of a series: a retention test on the
  // second day does not repeat the first day's trials stroke for stroke. The first session's seeds are
  // those of sessions made before protocols had several (plans hold at most kMaxPlannedTrials trials).
  const std::uint64_t position =
      trial.index + 1 + kMaxPlannedTrials * static_cast<std::uint64_t>(session.setup.session_number - 1);
  spec.seed = study_detail::mix64(session.setup.writer_seed ^ study_detail::mix64(position));
  const StudyProtocol& protocol = session.protocol.protocol;
  spec.rate_hz = protocol.trial.rate_hz;
  spec.max_duration_s = protocol.trial.max_duration_s;
  spec.pacing = session.setup.pacing;
  return spec;
}

TrialOptions study_trial_options(const SessionManifest& session, const StudyCondition& condition,
                                 const PlannedTrial& trial, const TrialGuidance& guidance) {
  const auto spec = Checked<TrialSpec>::check(study_trial_spec(session, condition, trial, guidance),
                                              study_teacher_source(condition));
  // The trial's whole trial, as its session makes it (on a device stating no limits), with a replay's
  // teacher, its runner's input, checked with the options holding it.
  return *whole_trial_options(study_detail::study_whole_trial(condition, guidance, spec, DeviceInfo{}),
                              guidance.teacher);
}

namespace {

// One run of a session's unsaved trials, in its steps: the run's start, each trial's break, scene, plan,
// device, run and keeping, and the run's end. Each step logs what it did to the session's log.
class SessionRun {
 public:
  SessionRun(SessionFolder& session, const SessionRunOptions& run_options, const DeviceRegistry& registry)
      : session_(session),
        options_(run_options),
        registry_(registry),
        manifest_(session.manifest()),
        listing_(registry.find(manifest_.setup.device)),  // only its backend is scanned
        simulated_writer_(manifest_.setup.writer == TrialWriter::simulated),
        // A learning simulated subject remembers its saved trials, of this session and the ones before it.
        learning_(simulated_writer_ && manifest_.setup.writer_learning == WriterLearning::two_state),
        standard_(CharacterLibrary::standard()) {
    check_plan(manifest_, listing_);
  }

  SessionRunResult run() {
    begin();
    for (const PlannedTrial& trial : session_.plan()) {
      if (session_.is_saved(trial)) continue;
      if (!rest_before(trial)) break;
      if (options_.host) options_.host->before_trial(trial, result_.planned);
      run_trial(trial);
      if (result_.interrupted || result_.device_failed || result_.save_failed) break;
    }
    end();
    return result_;
  }

 private:
  // What a trial runs with, made before its device is opened.
  struct PreparedTrial {
    Scene scene;
    study_detail::PreparedGuidance guidance;
    Checked<TrialSpec> spec;  // checked once, when the runner has added what it knows
    json started;
    std::optional<WriterSkills> skills;
  };

  void begin() {
    // Refused before the first trial rather than found when a trial cannot be saved.
    session_.check_writable();
    // The series' chain checked (a day before edited or replaced is refused) before the log is written to:
    // a refused run writes nothing.
    if (learning_) memory_ = study_detail::remembered(session_);
    result_.planned = session_.plan().size();
    result_.saved_before = session_.saved_count();
    const std::optional<std::size_t> first = session_.next_unsaved();
    if (result_.saved_before > 0) log_unlogged_saves(session_, logged_events(session_));
    session_.log(result_.saved_before == 0 ? "session_started" : "session_resumed",
                 json{{"saved_trials", result_.saved_before},
                      {"next_trial", first ? json(*first + 1) : json(nullptr)},
                      {"library", library_build().version}}
                     .dump());
  }

  // The break before `trial` (logged; waited for with a person); false when the run is to stop.
  bool rest_before(const PlannedTrial& trial) {
    if (stop_requested(options_)) {
      result_.interrupted = true;
      return false;
    }
    if (trial.break_before_s > 0.0 && ran_one_) {
      session_.log("break", json{{"before_trial", trial.index + 1},
                                 {"duration_s", trial.break_before_s},
                                 {"waited", !simulated_writer_}}
                                .dump());
      if (!simulated_writer_ && options_.host) {
        options_.host->rest(trial.break_before_s, trial, [this] { return stop_requested(options_); });
      }
      if (stop_requested(options_)) {
        result_.interrupted = true;
        return false;
      }
    }
    return true;
  }

  // An error before the trial runs (a character the library lacks, a device that does not open) is
  // logged, with the session's stop and its reason, before it ends the run.
  void log_failure(const PlannedTrial& trial, const Error& e, const char* reason) {
    json details = trial_details(trial);
    details["error"] = e.what();
    session_.log("trial_failed", json_text(details));
    session_.log("session_stopped", json{{"saved_trials", result_.saved_before + result_.saved_now},
                                         {"planned", result_.planned},
                                         {"reason", reason}}
                                        .dump());
  }

  // The character's model, fitted once per session run.
  const Character& character(char32_t code_point) {
    auto found = characters_.find(code_point);
    if (found == characters_.end()) {
      Character model =
          options_.load_character ? options_.load_character(code_point) : standard_.load(code_point);
      found = characters_.emplace(code_point, std::move(model)).first;
    }
    return found->second;
  }

  Scene scene_of(const PlannedTrial& trial) {
    std::vector<Character> models;
    try {
      for (const char32_t c : trial.characters) models.push_back(character(c));
    } catch (const Error& e) {
      log_failure(trial, e, "character_not_loaded");
      throw;
    }
    return Scene::lay_out(models);
  }

  // The trial's guidance, specification and (a learning subject's) skills, before its device is opened.
  PreparedTrial prepare(const PlannedTrial& trial, const StudyCondition& condition) {
    Scene scene = scene_of(trial);
    study_detail::PreparedGuidance guidance;
    if (study_detail::adapts_by_repetition(condition))
      guidance = study_detail::repetition_guidance(session_, condition, trial);
    if (replays_teacher(condition)) {
      try {
        guidance = study_detail::replay_guidance(session_, condition, trial, scene);
      } catch (const Error& e) {  // a teacher that cannot be read or recorded: logged as a character is
        log_failure(trial, e, "teacher_not_loaded");
        throw;
      }
    }
    TrialSpec spec = study_trial_spec(manifest_, condition, trial, guidance.guidance);
    if (options_.pacing) spec.pacing = *options_.pacing;
    if (!simulated_writer_ && spec.pacing != TrialPacing::lock_step)  // a person, in real time
      spec.watchdog_s = default_watchdog_s(listing_.capabilities.hardware);
    json started = trial_details(trial);
    std::optional<WriterSkills> skills;
    if (learning_) {
      skills = study_detail::learn_into(spec, memory_, study_detail::subject_profile(manifest_.setup), scene,
                                        trial.characters);
      started["shape_skill"] = skills->shape;
      started["order_skill"] = skills->order;
      started["timing_skill"] = skills->timing;
    }
    Checked<TrialSpec> checked = Checked<TrialSpec>::check(std::move(spec), study_teacher_source(condition));
    return PreparedTrial{std::move(scene), std::move(guidance), std::move(checked), std::move(started),
                         std::move(skills)};
  }

  std::unique_ptr<HapticDevice> create_device(const PlannedTrial& trial) {
    try {
      return registry_.create(manifest_.setup.device);
    } catch (const Error& e) {
      log_failure(trial, e, "device_not_opened");
      throw;
    }
  }

  // The runtime handles of the one runner: the device (made before, so that a failure is logged), the
  // teacher kept in the session folder and what the host gives (its display channel). The trial's every
  // parameter is its whole trial's (study_whole_trial), values made once before it runs.
  TrialRunInputs inputs_for(const PlannedTrial& trial, const PreparedTrial& prepared, const WholeTrial& whole,
                            HapticDevice& device) const {
    TrialRunInputs inputs;
    inputs.device = &device;
    inputs.teacher = prepared.guidance.guidance.teacher;
    inputs.should_stop = options_.should_stop;
    inputs.lock_memory = options_.lock_memory;
    if (options_.host != nullptr)
      inputs.display = options_.host->display_for(trial, whole.force_law.acceptance);
    return inputs;
  }

  void run_trial(const PlannedTrial& trial) {
    const StudyCondition& condition = manifest_.protocol.protocol.condition(trial.condition);
    PreparedTrial prepared = prepare(trial, condition);
    std::unique_ptr<HapticDevice> device = create_device(trial);
    session_.log("trial_started", json_text(prepared.started));
    // The simulated subject, with its traits and what it learned (the specification's writer part).
    SimulatedWriting writing(*prepared.spec);
    const Checked<WholeTrial> whole =
        study_detail::study_whole_trial(condition, prepared.guidance.guidance, prepared.spec, device->info());
    TrialRunInputs inputs = inputs_for(trial, prepared, *whole, *device);
    inputs.hand_maker = &writing;

    study_detail::TrialRecordContext context;
    context.session = &manifest_;
    context.trial = &trial;
    context.condition = &condition;
    context.device_name = manifest_.setup.device;
    context.hardware = listing_.capabilities.hardware;
    context.simulated_writer = simulated_writer_;
    context.guidance = study_detail::guidance_record_json(condition, prepared.guidance);
    context.writer_skills = prepared.skills;
    context.start_utc = utc_now_iso8601();
    const auto wall_start = std::chrono::steady_clock::now();
    TrialRun run = run_whole_trial(whole, prepared.scene, inputs);
    context.device_info = run.device;  // as it ran: a device that reads its limits on opening knows them now
    if (run.result.end == TrialEnd::interrupted && run.result.abort_reason.empty())
      run.result.abort_reason = "stopped by " + stop_reason(options_);
    context.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    context.end_utc = utc_now_iso8601();
    context.options = &run.options;
    context.spec = &*prepared.spec;
    context.simulation.writer = writing.profile();
    context.simulation.seed = prepared.spec->seed;
    context.writer_log = writing.log();
    device.reset();
    ran_one_ = true;

    const TrialOutcome outcome = keep(trial, condition, prepared.scene, run, context);
    if (options_.host) options_.host->after_trial(trial, outcome);
  }

  // Saves the trial (or keeps it as an attempt) with its record, and logs how it ended.
  TrialOutcome keep(const PlannedTrial& trial, const StudyCondition& condition, const Scene& scene,
                    const TrialRun& run, study_detail::TrialRecordContext& context) {
    const TrialResult& trial_result = run.result;
    const std::string stem = SessionFolder::trial_stem(trial);
    context.trace_file = stem + "." + std::string(SessionFolder::kTraceExtension);
    context.svg_file = stem + ".svg";
    const WritingMetrics& writing = run.metrics;
    std::vector<std::vector<QuizEvent>> quiz;
    if (condition.quiz) quiz = quiz_characters(scene, trial_result.trace, *condition.quiz);
    const bool keep_as_trial =
        trial_result.end == TrialEnd::completed || trial_result.end == TrialEnd::time_limit ||
        trial_result.end == TrialEnd::gave_up || trial_result.end == TrialEnd::writer_finished;
    TrialOutcome outcome;
    outcome.end_reason = to_string(trial_result.end);
    outcome.time_s = writing.total_time_s.value_or(std::nan(""));
    outcome.mean_deviation_mm = writing.deviation ? writing.deviation->mean_m * 1e3 : std::nan("");
    json details = trial_details(trial);
    details["end_reason"] = outcome.end_reason;
    // The trace's bytes first: the record names them by their SHA-256. Its image made in memory may fail
    // as a write does (HDF5 out of memory): the trial is then one that could not be saved, named as such.
    std::string trace;
    try {
      trace = trial_trace_hdf5(trial_result.trace);
    } catch (const DataError& e) {
      return save_failed(trial, e, outcome);
    }
    context.trace_sha256 = sha256_hex(trace);
    if (keep_as_trial) {
      const std::string record = study_detail::trial_record_json(context, scene, trial_result, writing,
                                                                 quiz.empty() ? nullptr : &quiz);
      try {
        session_.save_trial(trial, record, trace, trial_svg(scene, trial_result));
      } catch (const DataError& e) {
        return save_failed(trial, e, outcome);
      }
      // Learned from as the record says, the same as when the memory is rebuilt on a resume.
      if (learning_)
        study_detail::practise_record(memory_, json::parse(record),
                                      session_.trial_file(trial, "json").string(),
                                      study_detail::subject_traits(manifest_.setup).learning);
      outcome.saved = true;
      outcome.json_file = session_.trial_file(trial, "json").string();
      details["time_s"] = outcome.time_s;
      session_.log("trial_saved", json_text(details));
      ++result_.saved_now;
    } else {
      context.svg_file.clear();
      const auto record = [&](const std::string& trace_file) {
        context.trace_file = trace_file;  // the attempt's own, beside its record
        return study_detail::trial_record_json(context, scene, trial_result, writing,
                                               quiz.empty() ? nullptr : &quiz);
      };
      std::filesystem::path kept;
      try {
        kept = session_.save_attempt(trial, record, trace);
      } catch (const DataError& e) {
        return save_failed(trial, e, outcome);
      }
      outcome.json_file = kept.string();
      details["attempt"] = kept.filename().string();
      details["abort_reason"] = trial_result.abort_reason;
      ++result_.attempts_kept;
      if (trial_result.end == TrialEnd::interrupted) {
        details["reason"] = stop_reason(options_);
        session_.log("trial_interrupted", json_text(details));
        result_.interrupted = true;
      } else {
        session_.log("trial_failed", json_text(details));
        result_.device_failed = true;
        result_.failure = trial_result.abort_reason;
      }
    }
    return outcome;
  }

  // A trial that could not be saved (the disk filled meanwhile) stops the run: reported, logged where the
  // log can still be written, and left unsaved, so that a resume runs it again; nothing saved is touched.
  TrialOutcome save_failed(const PlannedTrial& trial, const DataError& e, TrialOutcome outcome) {
    result_.save_failed = true;
    result_.failure = "trial " + std::to_string(trial.index + 1) + " (" + SessionFolder::trial_stem(trial) +
                      ") could not be saved: " + e.what();
    json details = trial_details(trial);
    details["error"] = e.what();
    try {
      session_.log("trial_failed", json_text(details));
    } catch (const DataError&) {  // the same full disk: the failure is reported by the result
    }
    return outcome;
  }

  void end() {
    if (result_.save_failed) {
      try {
        session_.log("session_stopped", json{{"saved_trials", result_.saved_before + result_.saved_now},
                                             {"planned", result_.planned},
                                             {"reason", "save_failed"}}
                                            .dump());
      } catch (const DataError&) {  // as above
      }
      return;
    }
    if (result_.complete()) {
      session_.log("session_completed", json{{"trials", result_.planned}}.dump());
    } else {
      session_.log("session_stopped", json{{"saved_trials", result_.saved_before + result_.saved_now},
                                           {"planned", result_.planned},
                                           {"reason", result_.interrupted     ? stop_reason(options_)
                                                      : result_.device_failed ? std::string("device_fault")
                                                                              : std::string("unknown")}}
                                          .dump());
    }
  }

  SessionFolder& session_;
  const SessionRunOptions& options_;
  const DeviceRegistry& registry_;
  const SessionManifest& manifest_;
  const DeviceListing listing_;
  const bool simulated_writer_;
  const bool learning_;
  CharacterLibrary standard_;
  std::map<char32_t, Character> characters_;
  WriterMemory memory_;
  SessionRunResult result_;
  bool ran_one_ = false;
};

}  // namespace

SessionRunResult run_session(SessionFolder& session, const SessionRunOptions& run_options) {
  if (run_options.registry == nullptr) {
    throw InvalidArgument(
        "run_session: no device registry (SessionRunOptions::registry) to create the session's "
        "device \"" +
        session.manifest().setup.device + "\" from");
  }
  return SessionRun(session, run_options, *run_options.registry).run();
}

bool complete_session_log(SessionFolder& session) {
  if (session.next_unsaved()) return false;
  const std::vector<json> events = logged_events(session);
  if (!events.empty() && events.back().value("event", "") == "session_completed") return false;
  const std::size_t saved = session.saved_count();
  log_unlogged_saves(session, events);
  session.log(
      "session_resumed",
      json{{"saved_trials", saved}, {"next_trial", nullptr}, {"library", library_build().version}}.dump());
  session.log("session_completed", json{{"trials", session.plan().size()}}.dump());
  return true;
}

}  // namespace calligraphy
