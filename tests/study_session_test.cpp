// Study sessions end to end in the library: folders, the runner with a simulated writer, interruption and
// resumption without losing or overwriting a saved trial, the records, the report read back.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_reader.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/study/session_series.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/whole_trial.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "probe_device.hpp"
#include "study/manifest_json.hpp"
#include "study/saved_sessions.hpp"
#include "study/trial_guidance.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"

using namespace calligraphy;
namespace fs = std::filesystem;

namespace {

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

LoadedProtocol small_protocol(const std::string& extra_condition = "") {
  return protocol_from_text(
      R"({"name": "small", "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"},
          {"name": "quiz", "mode": "quiz"})" +
          extra_condition + R"(],
          "test": {"characters": ["十"], "conditions": ["vision", "haptic", "quiz"], "repetitions": 1},
          "trial": {"max_duration_s": 40}})",
      "small.json");
}

SessionSetup simulated(const std::string& id) {
  SessionSetup setup;
  setup.subject = {id, 1};
  setup.writer_seed = subject_seed(id);
  return setup;
}

// Stops once `after` trials ended (between trials).
struct StopAfter final : SessionHost {
  std::size_t after;
  std::size_t ended = 0;
  explicit StopAfter(std::size_t n) : after(n) {}
  void after_trial(const PlannedTrial&, const TrialOutcome&) override { ++ended; }
};

}  // namespace

TEST_CASE("a session stopped mid-trial resumes without losing or overwriting a saved trial",
          "[study][session]") {
  TempFolder temp;
  const LoadedProtocol protocol = small_protocol();
  fs::path folder;
  std::string first_json, first_trace;
  {
    SessionFolder session = SessionFolder::create(temp.path, simulated("S01"), protocol);
    folder = session.path();
    CHECK(folder.parent_path() == temp.path / "S01");
    REQUIRE(session.plan().size() == 3);
    // Another process (here: another open) cannot work on the session at the same time.
    CHECK_THROWS_AS(SessionFolder::open(folder), StateError);

    // Stop 2000 ticks into the second trial.
    StopAfter host(1);
    std::size_t polls = 0;
    SessionRunOptions options = study_test::run_options();
    options.host = &host;
    options.should_stop = [&] { return host.ended >= 1 && ++polls > 2000; };
    const SessionRunResult result = run_session(session, options);
    CHECK(result.interrupted);
    CHECK(result.saved_now == 1);
    CHECK(result.attempts_kept == 1);
    CHECK_FALSE(result.complete());
    const PlannedTrial& first = session.plan()[0];
    REQUIRE(session.is_saved(first));
    CHECK_FALSE(session.is_saved(session.plan()[1]));
    first_json = read(session.trial_file(first, "json"));
    first_trace = read(session.trial_file(first, SessionFolder::kTraceExtension));
    REQUIRE_FALSE(first_trace.empty());
    // A saved trial is never overwritten.
    CHECK_THROWS_AS(session.save_trial(first, "{}", "", ""), StateError);
    CHECK(read(session.trial_file(first, "json")) == first_json);
    const fs::path attempt =
        folder / "trials" / "attempts" / (SessionFolder::trial_stem(session.plan()[1]) + ".attempt-1.json");
    REQUIRE(fs::exists(attempt));
    // The attempt's record names the trace kept beside it, by name and SHA-256, not the trial's own name.
    const nlohmann::json attempt_record = nlohmann::json::parse(read(attempt));
    const std::string attempt_trace = attempt_record["files"]["trace"].get<std::string>();
    CHECK(attempt_trace == SessionFolder::trial_stem(session.plan()[1]) + ".attempt-1." +
                               std::string(SessionFolder::kTraceExtension));
    CHECK(attempt_record["files"]["trace_sha256"].get<std::string>() ==
          sha256_hex(read(attempt.parent_path() / attempt_trace)));
  }
  SessionFolder resumed = SessionFolder::open(folder);
  CHECK(resumed.next_unsaved() == std::optional<std::size_t>(1));
  const SessionRunResult result = run_session(resumed, study_test::run_options());
  CHECK(result.complete());
  CHECK(result.saved_before == 1);
  CHECK(result.saved_now == 2);
  CHECK(read(resumed.trial_file(resumed.plan()[0], "json")) == first_json);
  CHECK(read(resumed.trial_file(resumed.plan()[0], SessionFolder::kTraceExtension)) == first_trace);

  // The log: created, started, the interruption, resumed, completed; every line a JSON object.
  std::ifstream log(folder / "log.jsonl");
  std::vector<std::string> events;
  for (std::string line; std::getline(log, line);) events.push_back(nlohmann::json::parse(line).at("event"));
  CHECK(events.front() == "session_created");
  CHECK(std::count(events.begin(), events.end(), "trial_interrupted") == 1);
  CHECK(std::count(events.begin(), events.end(), "session_resumed") == 1);
  CHECK(std::count(events.begin(), events.end(), "trial_saved") == 3);
  CHECK(events.back() == "session_completed");

  // Every trial record carries the scores and the provenance.
  for (const PlannedTrial& trial : resumed.plan()) {
    const auto record = nlohmann::json::parse(read(resumed.trial_file(trial, "json")));
    for (const char* key :
         {"frechet_m", "dtw_m", "order_errors", "backwards_strokes", "total_time_s", "mean_deviation_m",
          "start_time_utc", "force_law", "renderer", "scene", "writer"}) {
      CHECK(record.contains(key));
    }
    CHECK(record["frechet_m"].is_number());
    CHECK(record["protocol"]["sha256"] == protocol.sha256);
    CHECK(record["device"]["info"]["max_force_n"].get<double>() > 0.0);
    CHECK(record["force_law"]["guidance"] == (trial.condition == "haptic"));
    CHECK(record["writer"]["kind"] == "simulated");
    CHECK(record["scene"]["characters"][0]["placement"]["metres_per_unit"].get<double>() > 0.0);
    CHECK(record["library"]["version"].is_string());
    CHECK(record.contains("quiz") == (trial.condition == "quiz"));
  }
}

TEST_CASE("a session stopped between trials starts no further trial", "[study][session]") {
  TempFolder temp;
  SessionFolder session = SessionFolder::create(temp.path, simulated("S02"), small_protocol());
  StopAfter host(1);
  SessionRunOptions options = study_test::run_options();
  options.host = &host;
  options.should_stop = [&] { return host.ended >= 1; };
  const SessionRunResult result = run_session(session, options);
  CHECK(result.interrupted);
  CHECK(result.saved_now == 1);
  CHECK(result.attempts_kept == 0);
}

namespace {

// The log's events of `folder`, as JSON objects.
std::vector<nlohmann::json> log_events(const fs::path& folder) {
  std::ifstream log(folder / "log.jsonl");
  std::vector<nlohmann::json> events;
  for (std::string line; std::getline(log, line);) events.push_back(nlohmann::json::parse(line));
  return events;
}

const nlohmann::json& only_event(const std::vector<nlohmann::json>& events, const std::string& name) {
  const auto is = [&name](const nlohmann::json& e) { return e.at("event") == name; };
  REQUIRE(std::count_if(events.begin(), events.end(), is) == 1);
  return *std::find_if(events.begin(), events.end(), is);
}

}  // namespace

TEST_CASE("a session stopped mid-trial logs why, and the attempt says it", "[study][session]") {
  TempFolder temp;
  SessionFolder session = SessionFolder::create(temp.path, simulated("S05"), small_protocol());
  std::size_t polls = 0;
  SessionRunOptions options = study_test::run_options();
  options.should_stop = [&] { return ++polls > 500; };
  options.stop_reason = [] { return std::string("display_lost"); };
  const SessionRunResult result = run_session(session, options);
  CHECK(result.interrupted);
  CHECK(result.attempts_kept == 1);
  const std::vector<nlohmann::json> events = log_events(session.path());
  CHECK(only_event(events, "trial_interrupted")["reason"] == "display_lost");
  CHECK(only_event(events, "session_stopped")["reason"] == "display_lost");
  const fs::path attempt = session.path() / "trials" / "attempts" /
                           (SessionFolder::trial_stem(session.plan()[0]) + ".attempt-1.json");
  const auto record = nlohmann::json::parse(read(attempt));
  CHECK(record["end_reason"] == "interrupted");
  CHECK(record["abort_reason"] == "stopped by display_lost");

  // Without a reason: "interrupted", as before.
  SessionFolder other = SessionFolder::create(temp.path, simulated("S06"), small_protocol());
  polls = 0;
  options.stop_reason = nullptr;
  CHECK(run_session(other, options).interrupted);
  CHECK(only_event(log_events(other.path()), "session_stopped")["reason"] == "interrupted");
}

TEST_CASE("a character that cannot be loaded mid-session is logged before the error ends the run",
          "[study][session]") {
  TempFolder temp;
  SessionFolder session = SessionFolder::create(temp.path, simulated("S07"), small_protocol());
  SessionRunOptions options = study_test::run_options();
  options.load_character = [](char32_t) -> Character { throw DataError("no such character in the data"); };
  CHECK_THROWS_WITH(run_session(session, options), Catch::Contains("no such character"));
  const std::vector<nlohmann::json> events = log_events(session.path());
  const nlohmann::json& failed = only_event(events, "trial_failed");
  CHECK(failed["trial"] == 1);
  CHECK(failed["error"] == "no such character in the data");
  CHECK(only_event(events, "session_stopped")["reason"] == "character_not_loaded");
  CHECK(session.saved_count() == 0);
}

TEST_CASE("a device lost mid-trial keeps the attempt and stops the session naming the fault",
          "[study][session]") {
  TempFolder temp;
  SessionSetup setup = simulated("S07");
  setup.device = "probe";
  SessionFolder session = SessionFolder::create(temp.path, setup, small_protocol());
  DeviceRegistry registry;
  registry.register_device(
      "probe", test::ProbeDevice().info(),
      [] { return std::make_unique<test::ProbeDevice>(/*fail_on_read=*/700); },
      DeviceCapabilities{.moved_by_simulated_hand = true});
  SessionRunOptions options = study_test::run_options();
  options.registry = &registry;
  const SessionRunResult result = run_session(session, options);
  CHECK(result.device_failed);
  CHECK(result.failure.find("link lost") != std::string::npos);  // DeviceFault::link_lost's message
  CHECK(result.attempts_kept == 1);
  CHECK(result.saved_now == 0);
  const std::vector<nlohmann::json> events = log_events(session.path());
  CHECK(only_event(events, "trial_failed")["end_reason"] == "device_fault");
  CHECK(only_event(events, "session_stopped")["reason"] == "device_fault");
  const fs::path attempt =
      session.path() / "trials" / "attempts" / (SessionFolder::trial_stem(session.plan()[0]) + ".attempt-1");
  const auto record = nlohmann::json::parse(read(fs::path(attempt.string() + ".json")));
  CHECK(record["end_reason"] == "device_fault");
  // The attempt's trace, saved as a trial's: every tick before the lost read.
  CHECK(read_trace_hdf5(attempt.string() + "." + std::string(SessionFolder::kTraceExtension)).size() == 700);
}

TEST_CASE("a device that does not open is logged with the session's stop before the error ends the run",
          "[study][session]") {
  TempFolder temp;
  SessionSetup setup = simulated("S08");
  setup.device = "unplugged";
  SessionFolder session = SessionFolder::create(temp.path, setup, small_protocol());
  DeviceRegistry registry;
  registry.register_device("unplugged", test::ProbeDevice().info(), []() -> std::unique_ptr<HapticDevice> {
    throw DeviceError("the device is not connected");
  });
  SessionRunOptions options = study_test::run_options();
  options.registry = &registry;
  CHECK_THROWS_WITH(run_session(session, options), Catch::Contains("not connected"));
  const std::vector<nlohmann::json> events = log_events(session.path());
  CHECK(only_event(events, "trial_failed")["error"] == "the device is not connected");
  CHECK(only_event(events, "session_stopped")["reason"] == "device_not_opened");
  CHECK(session.saved_count() == 0);
}

TEST_CASE("a simulated subject writes the same for the same id and differently for another",
          "[study][session]") {
  TempFolder temp;
  const LoadedProtocol protocol = small_protocol();
  std::vector<std::string> times;
  for (const char* id : {"A1", "A1", "B1"}) {
    SessionFolder session = SessionFolder::create(temp.path, simulated(id), protocol);
    run_session(session, study_test::run_options());
    const auto record = nlohmann::json::parse(read(session.trial_file(session.plan()[0], "json")));
    times.push_back(record["per_stroke"].dump() + record["total_time_s"].dump());
  }
  CHECK(times[0] == times[1]);
  CHECK(times[0] != times[2]);
}

namespace {

nlohmann::json record_of(const SessionFolder& session, const PlannedTrial& trial) {
  return nlohmann::json::parse(read(session.trial_file(trial, "json")));
}

LoadedProtocol fading_protocol() {
  return protocol_from_text(
      R"({"name": "f", "conditions": [{"name": "fade", "mode": "fading",
            "parameters": {"start_gain": 0.9, "forgetting_factor": 0.7, "error_gain_per_m": 150}}],
          "test": {"characters": ["十", "人"], "conditions": ["fade"], "repetitions": 3},
          "trial": {"max_duration_s": 40}})",
      "f.json");
}

}  // namespace

TEST_CASE("a fading gain follows the previous repetition of the item, the same after a resume",
          "[study][session][guidance]") {
  TempFolder temp;
  const LoadedProtocol protocol = fading_protocol();
  // One session run straight through, one stopped after two trials and resumed: the same subject.
  SessionFolder whole = SessionFolder::create(temp.path / "whole", simulated("F1"), protocol);
  REQUIRE(run_session(whole, study_test::run_options()).complete());
  fs::path folder;
  {
    SessionFolder session = SessionFolder::create(temp.path / "resumed", simulated("F1"), protocol);
    folder = session.path();
    StopAfter host(2);
    SessionRunOptions options = study_test::run_options();
    options.host = &host;
    options.should_stop = [&] { return host.ended >= 2; };
    REQUIRE(run_session(session, options).saved_now == 2);
  }
  SessionFolder resumed = SessionFolder::open(folder);
  REQUIRE(run_session(resumed, study_test::run_options()).complete());

  const StudyCondition& fade = protocol.protocol.condition("fade");
  std::map<std::u32string, std::pair<double, double>> previous;  // item -> (gain, mean deviation [mm])
  for (const PlannedTrial& trial : whole.plan()) {
    const auto record = record_of(whole, trial);
    const double gain = record["guidance"]["gain"].get<double>();
    CHECK(record["force_law"]["guidance_gain"].get<double>() == gain);
    CHECK(record["force_law"]["guidance_mode"] == "fading");
    const auto before = previous.find(trial.characters);
    if (before == previous.end()) {
      CHECK(gain == fade.guidance.value().schedule.value().start_gain);
      CHECK(record["guidance"]["previous_trial"].is_null());
    } else {
      CHECK(gain == next_guidance_gain(before->second.first, before->second.second,
                                       fade.guidance.value().schedule.value().fading_rule));
    }
    previous[trial.characters] = {gain, record["mean_deviation_m"].get<double>()};
    CHECK(record_of(resumed, trial)["guidance"] == record["guidance"]);
  }
}

TEST_CASE("an assist band and a skill-adaptive mode follow the previous repetition, the same after a resume",
          "[study][session][guidance]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "a", "conditions": [
            {"name": "band", "mode": "assist-as-needed",
             "parameters": {"start_band_m": 0.002, "target_error_m": 0.001, "band_rate": 2}},
            {"name": "adapt", "mode": "skill-adaptive", "parameters": {"threshold_m": 0.0012}},
            {"name": "pace", "mode": "timing", "parameters": {"speed_m_s": 0.03}}],
          "test": {"characters": ["十", "人"], "conditions": ["band", "adapt", "pace"], "repetitions": 3},
          "trial": {"max_duration_s": 40}})",
      "a.json");
  SessionFolder whole = SessionFolder::create(temp.path / "whole", simulated("A1"), protocol);
  REQUIRE(run_session(whole, study_test::run_options()).complete());
  fs::path folder;
  {
    SessionFolder session = SessionFolder::create(temp.path / "resumed", simulated("A1"), protocol);
    folder = session.path();
    StopAfter host(4);
    SessionRunOptions options = study_test::run_options();
    options.host = &host;
    options.should_stop = [&] { return host.ended >= 4; };
    REQUIRE(run_session(session, options).saved_now == 4);
  }
  SessionFolder resumed = SessionFolder::open(folder);
  REQUIRE(run_session(resumed, study_test::run_options()).complete());

  const StudyCondition& band = protocol.protocol.condition("band");
  const StudyCondition& adapt = protocol.protocol.condition("adapt");
  // condition and item -> (band [m], mean deviation [m]) of the previous repetition
  std::map<std::pair<std::string, std::u32string>, std::pair<double, double>> previous;
  std::set<std::string> adaptive_modes;
  for (const PlannedTrial& trial : whole.plan()) {
    const auto record = record_of(whole, trial);
    const auto key = std::make_pair(trial.condition, trial.characters);
    const auto before = previous.find(key);
    const double deviation_m = record["mean_deviation_m"].get<double>();
    if (trial.condition == "band") {
      const double b = record["guidance"]["band_m"].get<double>();
      CHECK(record["force_law"]["guidance_mode"] == "assist-as-needed");
      CHECK(record["force_law"]["assist_band_m"].get<double>() == b);
      CHECK(b == (before == previous.end()
                      ? band.guidance.value().schedule.value().start_band_m
                      : next_assist_band(before->second.first, before->second.second,
                                         band.guidance.value().schedule.value().assist_rule)));
      previous[key] = {b, deviation_m};
    } else if (trial.condition == "adapt") {
      const std::string selected = record["guidance"]["selected_mode"].get<std::string>();
      CHECK(record["force_law"]["guidance_mode"] == selected);
      const std::string expected =
          before == previous.end()
              ? "fixed"
              : to_string(skill_adaptive_mode(before->second.second,
                                              adapt.guidance.value().schedule.value().skill_rule));
      CHECK(selected == expected);
      adaptive_modes.insert(selected);
      previous[key] = {0.0, deviation_m};
    } else {
      CHECK(record["force_law"]["guidance_mode"] == "timing");
      CHECK(record["force_law"]["timing_speed_m_s"].get<double>() == 0.03);
    }
    CHECK(record_of(resumed, trial)["guidance"] == record["guidance"]);
  }
  CHECK(adaptive_modes.count("fixed") == 1);
}

TEST_CASE("a replay condition follows a teacher kept in the session folder and names its SHA-256",
          "[study][session][guidance]") {
  TempFolder temp;
  const std::string conditions =
      R"({"name": "r", "conditions": [{"name": "play", "mode": "replay"TEACHERS}],
          "test": {"characters": ["十"], "conditions": ["play"], "repetitions": 1},
          "trial": {"max_duration_s": 40}})";
  const auto protocol_with = [&](const std::string& teachers) {
    std::string text = conditions;
    text.replace(text.find("TEACHERS"), 8, teachers);
    const fs::path path = temp.path / "protocols" / "r.json";
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
    return load_study_protocol(path);
  };
  // No teacher in the protocol: a skilled simulated writer records one into the session folder.
  SessionFolder recorded = SessionFolder::create(temp.path / "a", simulated("R1"), protocol_with(""));
  REQUIRE(run_session(recorded, study_test::run_options()).complete());
  const fs::path teacher_file = recorded.path() / "teachers" / "play-U5341.json";
  REQUIRE(fs::exists(teacher_file));
  const auto record = record_of(recorded, recorded.plan()[0]);
  CHECK(record["force_law"]["guidance_mode"] == "replay");
  CHECK(record["guidance"]["teacher"]["file"] == "teachers/play-U5341.json");
  CHECK(record["guidance"]["teacher"]["source"] == "recorded");
  CHECK(record["guidance"]["teacher"]["sha256"] == sha256_hex(read(teacher_file)));
  CHECK(record["completed_in_order"] == true);

  // The protocol's teacher (a path relative to the protocol file) is copied and named.
  fs::create_directories(temp.path / "protocols" / "t");
  fs::copy_file(teacher_file, temp.path / "protocols" / "t" / "shi.json");
  SessionFolder given = SessionFolder::create(temp.path / "b", simulated("R1"),
                                              protocol_with(R"(, "teachers": {"十": "t/shi.json"})"));
  REQUIRE(run_session(given, study_test::run_options()).complete());
  const auto given_record = record_of(given, given.plan()[0]);
  CHECK(given_record["guidance"]["teacher"]["source"] == "t/shi.json");
  CHECK(given_record["guidance"]["teacher"]["sha256"] == sha256_hex(read(teacher_file)));
  CHECK(read(given.path() / "teachers" / "play-U5341.json") == read(teacher_file));

  // A recording of another character is refused before the trial runs.
  std::string other = read(teacher_file);
  other.replace(other.find("\"十\""), std::string("\"十\"").size(), "\"人\"");
  std::ofstream(temp.path / "protocols" / "t" / "ren.json") << other;
  SessionFolder wrong = SessionFolder::create(temp.path / "c", simulated("R1"),
                                              protocol_with(R"(, "teachers": {"十": "t/ren.json"})"));
  CHECK_THROWS_WITH(run_session(wrong, study_test::run_options()),
                    Catch::Contains("condition 'play'") && Catch::Contains("人"));
  CHECK(wrong.saved_count() == 0);
}

TEST_CASE("two subjects' sessions started in the same second have different ids", "[study][session]") {
  TempFolder temp;
  const LoadedProtocol protocol = small_protocol();
  // The ids end in the UTC second the session began: made back to back, two sessions share it (a few
  // tries cover a second's turn between them).
  for (int attempt = 0; attempt < 5; ++attempt) {
    const fs::path root = temp.path / std::to_string(attempt);
    const SessionFolder first = SessionFolder::create(root, simulated("S01"), protocol);
    const SessionFolder second = SessionFolder::create(root, simulated("S02"), protocol);
    const std::string a = first.manifest().session_id, b = second.manifest().session_id;
    CHECK(a.starts_with(protocol.protocol.name + "-S01-"));
    CHECK(b.starts_with(protocol.protocol.name + "-S02-"));
    if (a.substr(a.size() - 15) != b.substr(b.size() - 15)) continue;  // another second
    CHECK(a != b);
    CHECK(first.path().filename() == a);  // the folder's name is the id
    return;
  }
  FAIL("five pairs of sessions made back to back never began in the same second");
}

TEST_CASE("a damaged session.json is refused naming the file and the JSON pointer", "[study][session]") {
  TempFolder temp;
  fs::path folder;
  {
    SessionFolder session = SessionFolder::create(temp.path, simulated("S04"), small_protocol());
    folder = session.path();
  }
  auto manifest = nlohmann::json::parse(read(folder / "session.json"));
  manifest["protocol"]["text"] = manifest["protocol"]["text"].get<std::string>() + " ";
  std::ofstream(folder / "session.json") << manifest.dump();
  CHECK_THROWS_WITH(SessionFolder::open(folder),
                    Catch::Contains("session.json: /protocol/text") && Catch::Contains("SHA-256"));
  std::ofstream(folder / "session.json") << "{\"format\": \"calligraphy-study-session\"}";
  CHECK_THROWS_WITH(SessionFolder::open(folder), Catch::Contains("session.json: /version"));
  CHECK_THROWS_AS(SessionFolder::create(temp.path, simulated("no/slash"), small_protocol()), InvalidArgument);
}

TEST_CASE("the per-trial pages of saved sessions: a trajectory and a force figure per trial, no summary",
          "[study][report]") {
  TempFolder temp;
  const LoadedProtocol protocol = small_protocol();
  for (const char* id : {"S01", "S02"}) {
    SessionFolder session = SessionFolder::create(temp.path / "study", simulated(id), protocol);
    run_session(session, study_test::run_options());
  }
  const StudyReportSessions study = list_report_sessions({temp.path / "study"});
  REQUIRE(study.sessions.size() == 2);
  CHECK(study.index.sessions.size() == 2);
  CHECK(study.sessions[0].shown.subject == "S01");
  CHECK(study.sessions[0].shown.saved == 3);
  CHECK(study.sessions[0].shown.conditions == std::vector<std::string>{"vision", "haptic", "quiz"});
  // Session ids name the subject: two subjects' sessions started in the same second differ.
  CHECK(study.sessions[0].shown.session != study.sessions[1].shown.session);
  std::size_t trials = 0;
  for (const ReportedSession& session : study.sessions) {
    SessionPageHtml page(session.shown, study.index.title, "../../index.html");
    std::size_t number = 0;
    read_session_trials(session, [&](const ReportTrial& trial) {
      ++number;
      CHECK(trial.index == number);  // 1-based, in planned order
      CHECK(trial.session == session.shown.session);
      CHECK(trial.time_s.size() == trial.position_m.size());
      CHECK_FALSE(trial.time_s.empty());
      CHECK(trial.reference_m.size() == 2);
      CHECK(trial.strokes.size() == 2);
      CHECK(trial.repetition >= 1);
      CHECK(trial.item >= 1);
      CHECK(trial.block >= 1);
      page.add(trial);
    });
    trials += number;
    const std::string text = page.finish();
    const auto count = [&](const std::string& needle) {
      std::size_t n = 0;
      for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
      return n;
    };
    CHECK(count("<figure class=\"trajectory\"") == 3);
    CHECK(count("<figure class=\"force\"") == 3);
    CHECK(count("<table") == 0);  // no summary over trials: the study report's
    CHECK(count("learning-curve") == 0);
    for (std::size_t n = 1; n <= 3; ++n)
      CHECK(count("id=\"" + trial_anchor(session.shown.session, n) + "\"") == 1);
    CHECK(text.find("http") == text.find("http://www.w3.org/2000/svg"));  // only the SVG namespace
  }
  CHECK(trials == 6);
  const std::string index = study_index_html(study.index, "trials.html");
  CHECK(index.find(session_page_path("trials.html", "S02", study.sessions[1].shown.session)) !=
        std::string::npos);
  CHECK(session_page_path("trials.html", "S01", "p-S01-1") == "trials_files/S01/p-S01-1.html");
  CHECK(trial_anchor("p-S01-1", 7) == "trial-p-S01-1-7");
  CHECK_THROWS_AS(list_report_sessions({temp.path / "nothing-here"}), DataError);
}

TEST_CASE("the per-trial pages escape what sessions wrote", "[study][report]") {
  StudyReportIndex index;
  index.title = "<script>alert(1)</script>";
  ReportSession session;
  session.subject = "S<1>";
  session.session = "s\"1";
  session.conditions = {"a"};
  index.sessions = {session};
  ReportTrial trial;
  trial.subject = "S<1>";
  trial.session = "s\"1";
  trial.condition = "a";
  trial.phase = "test";
  trial.characters = "\"&'";
  trial.time_s = {0.0, 1.0};
  trial.position_m = {Vec2::Zero(), Vec2(0.01, 0.0)};
  trial.pen_down = {true, true};
  trial.in_plane_force_n = {0.0, 1.0};
  SessionPageHtml page(session, index.title, "../../index.html");
  page.add(trial);
  for (const std::string& text : {page.finish(), study_index_html(index, "index.html")}) {
    CHECK(text.find("<script>") == std::string::npos);
    CHECK(text.find("&lt;script&gt;") != std::string::npos);
    CHECK(text.find("S&lt;1&gt;") != std::string::npos);
  }
  SessionPageHtml again(session, index.title, "../../index.html");
  again.add(trial);
  const std::string text = again.finish();
  CHECK(text.find("&quot;&amp;&#39;") != std::string::npos);
  CHECK(text.find("id=\"trial-s&quot;1-1\"") != std::string::npos);
  CHECK(study_index_html(index, "index.html").find("href=\"index_files/S%3C1%3E/s%221.html\"") !=
        std::string::npos);
}

TEST_CASE("a crash between saving a trial and logging it, or in a log line, is mended on resume",
          "[study][session]") {
  TempFolder temp;
  fs::path folder;
  {
    SessionFolder session = SessionFolder::create(temp.path, simulated("S05"), small_protocol());
    folder = session.path();
    StopAfter host(1);
    SessionRunOptions options = study_test::run_options();
    options.host = &host;
    options.should_stop = [&] { return host.ended >= 1; };
    REQUIRE(run_session(session, options).saved_now == 1);
  }
  // As if the process died after the trial's JSON was linked but before its log line, in the middle of a
  // later line.
  std::string kept;
  {
    std::ifstream log(folder / "log.jsonl");
    for (std::string line; std::getline(log, line);) {
      if (nlohmann::json::parse(line).at("event") != "trial_saved") kept += line + "\n";
    }
  }
  std::ofstream(folder / "log.jsonl", std::ios::trunc) << kept << "{\"event\": \"tri";
  SessionFolder resumed = SessionFolder::open(folder);
  REQUIRE(run_session(resumed, study_test::run_options()).complete());
  std::ifstream log(folder / "log.jsonl");
  std::size_t saved = 0, recovered = 0, torn = 0;
  for (std::string line; std::getline(log, line);) {
    if (!nlohmann::json::accept(line)) {
      ++torn;
      continue;
    }
    const auto event = nlohmann::json::parse(line);
    if (event.at("event") == "trial_saved") {
      ++saved;
      recovered += event.value("recovered", false) ? 1 : 0;
    }
  }
  CHECK(torn == 1);  // the torn line stands alone, every later line is whole
  CHECK(saved == 3);
  CHECK(recovered == 1);
}

TEST_CASE("a session's simulated writer is any known profile", "[study][session]") {
  TempFolder temp;
  SessionSetup setup = simulated("W1");
  setup.writer_profile = "foreign";
  SessionFolder session = SessionFolder::create(temp.path, setup, small_protocol());
  run_session(session, study_test::run_options());
  REQUIRE(session.is_saved(session.plan()[0]));
  CHECK(record_of(session, session.plan()[0])["writer"]["profile"]["name"] == "foreign");
  setup.writer_profile = "expert";
  CHECK_THROWS_WITH(SessionFolder::create(temp.path, setup, small_protocol()),
                    Catch::Contains("expert") && Catch::Contains("skilled"));
}

TEST_CASE("a protocol over two days: sessions linked, the delay recorded, groups and phases in the tables",
          "[study][session][phases]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "days", "conditions": [{"name": "free", "mode": "vision"}, {"name": "fixture", "mode": "haptic"},
          {"name": "fading", "mode": "fading"}],
          "phases": [
            {"phase": "pre-test", "condition": "free", "characters": ["十"]},
            {"phase": "training", "conditions": ["fixture", "fading"], "assignment": "between-subjects",
             "characters": ["十"]},
            {"phase": "post-test", "condition": "free", "characters": ["十"]},
            {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 86400},
            {"phase": "transfer", "condition": "free", "characters": ["人"], "session": 2}],
          "trial": {"max_duration_s": 40}})",
      "days.json");
  SessionSetup setup = simulated("S1");
  SessionSeries series = session_series(temp.path, "S1", protocol);
  CHECK(series.next == 1);
  CHECK(series.sessions == 2);
  CHECK(series.due());
  // A later session needs the one before it.
  setup.session_number = 2;
  CHECK_THROWS_WITH(SessionFolder::create(temp.path, setup, protocol), Catch::Contains("needs the previous"));
  setup.session_number = 1;

  std::string first_id;
  {
    SessionFolder first = SessionFolder::create(temp.path, setup, protocol);
    first_id = first.manifest().session_id;
    CHECK(first.manifest().group == "fixture");
    StopAfter host(1);
    SessionRunOptions options = study_test::run_options();
    options.host = &host;
    options.should_stop = [&host] { return host.ended >= 1; };
    REQUIRE_FALSE(run_session(first, options).complete());
  }
  series = session_series(temp.path, "S1", protocol);
  REQUIRE(series.unfinished);  // resumed before the next session starts
  CHECK(series.next == 1);
  {
    SessionFolder first = SessionFolder::open(*series.unfinished);
    REQUIRE(run_session(first, study_test::run_options()).complete());
  }
  series = session_series(temp.path, "S1", protocol);
  CHECK_FALSE(series.unfinished);
  REQUIRE(series.next == 2);
  REQUIRE(series.previous);
  CHECK(series.previous->session_id == first_id);
  CHECK(series.previous->delay_s == 86400.0);
  CHECK(series.previous->elapsed_s >= 0.0);
  CHECK(series.previous->elapsed_s < 3600.0);
  CHECK_FALSE(series.due());

  PreviousSession previous = *series.previous;
  previous.delay = SessionDelay::simulated;
  setup.session_number = 2;
  fs::path second_folder;
  {
    SessionFolder second = SessionFolder::create(temp.path, setup, protocol, previous);
    second_folder = second.path();
    REQUIRE(second.plan().size() == 2);
    REQUIRE(run_session(second, study_test::run_options()).complete());
  }
  const SessionFolder reopened = SessionFolder::open(second_folder);
  REQUIRE(reopened.manifest().previous);
  CHECK(reopened.manifest().previous->session_id == first_id);
  CHECK(reopened.manifest().previous->delay == SessionDelay::simulated);
  CHECK(reopened.manifest().setup.session_number == 2);
  series = session_series(temp.path, "S1", protocol);
  CHECK(series.next == 3);
  CHECK(series.folders.size() == 2);

  const StudyTables tables = read_study_tables({temp.path});
  REQUIRE(tables.trials.size() == 5);
  std::vector<std::string> phases;
  for (const TrialRow& row : tables.trials) {
    phases.push_back(row.phase);
    CHECK(row.group == "fixture");
    CHECK(row.session_number == (row.phase == "retention" || row.phase == "transfer" ? 2 : 1));
  }
  CHECK(phases == std::vector<std::string>{"pre-test", "training", "post-test", "retention", "transfer"});
  CHECK(tables.trials[1].condition == "fixture");
}

TEST_CASE("a learning simulated subject writes with what it learned, the same after a resume and a day later",
          "[study][session][phases][memory]") {
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "learn", "conditions": [{"name": "free", "mode": "vision"}],
          "phases": [
            {"phase": "training", "condition": "free", "characters": ["十"], "repetitions": 4},
            {"phase": "post-test", "condition": "free", "characters": ["十"]},
            {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 86400}],
          "trial": {"max_duration_s": 40}})",
      "learn.json");
  // Both days of subject L1 under `root`; the first day stopped after `stop_after` trials and resumed.
  const auto run_days = [&protocol](const fs::path& root, std::size_t stop_after) {
    SessionSetup setup = simulated("L1");
    setup.writer_learning = WriterLearning::two_state;
    setup.individual_differences = false;  // compared with the novice profile's own fields below
    fs::path first_folder;
    {
      SessionFolder first = SessionFolder::create(root, setup, protocol);
      first_folder = first.path();
      if (stop_after > 0) {
        StopAfter host(stop_after);
        SessionRunOptions options = study_test::run_options();
        options.host = &host;
        options.should_stop = [&host] { return host.ended >= host.after; };
        REQUIRE_FALSE(run_session(first, options).complete());
      }
    }
    SessionFolder first = SessionFolder::open(first_folder);
    REQUIRE(run_session(first, study_test::run_options()).complete());
    const SessionSeries series = session_series(root, "L1", protocol);
    REQUIRE(series.previous);
    PreviousSession previous = *series.previous;
    previous.delay = SessionDelay::simulated;
    setup.session_number = 2;
    SessionFolder second = SessionFolder::create(root, setup, protocol, previous);
    REQUIRE(run_session(second, study_test::run_options()).complete());
    // Each saved trial's bias, as its record's writer profile says, in order.
    std::vector<double> bias;
    for (const TrialRow& row : read_study_tables({root}).trials) {
      REQUIRE(row.shape_skill);  // the skill the trial started with, in the tables
      CHECK(*row.shape_skill >= 0.0);
      CHECK(*row.shape_skill < 1.0);
      REQUIRE(row.timing_skill);
      CHECK(*row.timing_skill >= 0.0);
      CHECK(*row.timing_skill < 1.0);
      const nlohmann::json record = nlohmann::json::parse(
          read(fs::path(row.trace_file).replace_extension().replace_extension(".json")));
      bias.push_back(record["writer"]["profile"]["bias_offset_m"].get<double>());
    }
    return bias;
  };
  TempFolder temp;
  const std::vector<double> straight = run_days(temp.path / "straight", 0);
  const std::vector<double> resumed = run_days(temp.path / "resumed", 2);
  REQUIRE(straight.size() == 6);
  CHECK(resumed == straight);  // rebuilt from the records, the memory is the one a straight run had
  const double own = WriterProfile::novice().bias_offset_m;
  CHECK(straight[0] == own);  // nothing learned before the first trial
  for (std::size_t i = 1; i < 5; ++i) CHECK(straight[i] < straight[i - 1]);  // practice lowers the bias
  CHECK(straight[5] > straight[4]);  // a day later the fast state is gone...
  CHECK(straight[5] < own);          // ...and the slow one kept
}

TEST_CASE("a learning subject's guidance takes shape and timing apart: the fixture shape, a replay both",
          "[study][session][memory]") {
  // The same subject trained three times on 十 under each condition; the skills its last trial started with.
  const auto skills_after = [](const std::string& mode) {
    TempFolder temp;
    const LoadedProtocol protocol =
        protocol_from_text(R"({"name": "apart", "conditions": [{"name": "c", "mode": ")" + mode + R"("}],
            "phases": [{"phase": "training", "condition": "c", "characters": ["十"], "repetitions": 3}],
            "trial": {"max_duration_s": 40}})",
                           "apart.json");
    SessionSetup setup = simulated("A1");
    setup.writer_learning = WriterLearning::two_state;
    SessionFolder session = SessionFolder::create(temp.path, setup, protocol);
    REQUIRE(run_session(session, study_test::run_options()).complete());
    const TrialRow last = read_study_tables({temp.path}).trials.back();
    REQUIRE(last.shape_skill);
    REQUIRE(last.timing_skill);
    return std::pair{*last.shape_skill, *last.timing_skill};
  };
  const auto [alone_shape, alone_timing] = skills_after("vision");
  const auto [fixture_shape, fixture_timing] = skills_after("haptic");
  const auto [replay_shape, replay_timing] = skills_after("replay");
  CHECK(alone_timing < alone_shape);  // vision shows the writer only part of its timing error
  CHECK(fixture_shape < alone_shape);
  CHECK(fixture_timing == Approx(alone_timing));  // the fixture pulls to the nearest point: no timing
  CHECK(replay_shape < alone_shape);              // the guidance hypothesis, for shape
  // The teacher's point at the teacher's time paces the writer and demonstrates the timing: more timing
  // learned than from vision (the direction of Feygin, Keehner & Tendick 2002).
  CHECK(replay_timing > alone_timing);
}

TEST_CASE("a condition's force law reaches the trial record through the one builder of a study trial",
          "[study][session][whole_trial]") {
  TempFolder temp;
  // A guidance stiffness the specification does not state, and a quiz's acceptance: the condition's parts.
  const LoadedProtocol protocol = protocol_from_text(
      R"({"name": "parts", "conditions": [{"name": "vision", "mode": "vision"},
            {"name": "stiff", "mode": "haptic", "guidance_stiffness_n_per_m": 300},
            {"name": "quiz", "mode": "quiz", "quiz": {"hint_after_misses": 1}}],
          "test": {"characters": ["十"], "conditions": ["vision", "stiff", "quiz"], "repetitions": 1},
          "trial": {"max_duration_s": 40}})",
      "parts.json");
  SessionFolder session = SessionFolder::create(temp.path / "s", simulated("W1"), protocol);
  const std::vector<PlannedTrial> plan = session.plan();
  REQUIRE(plan.size() == 3);
  REQUIRE(run_session(session, study_test::run_options()).complete());
  const DeviceInfo figures = study_test::registry().create(session.manifest().setup.device)->info();
  std::size_t compared = 0;
  for (const PlannedTrial& trial : plan) {
    const StudyCondition& condition = protocol.protocol.condition(trial.condition);
    const auto spec = Checked<TrialSpec>::check(study_trial_spec(session.manifest(), condition, trial),
                                                study_teacher_source(condition));
    const Checked<WholeTrial> whole = study_detail::study_whole_trial(condition, {}, spec, figures);
    const RecordedTrial recorded = read_study_recorded_trial(session.trial_file(trial, "json").string());
    CHECK(recorded.force_law.guidance_stiffness_n_per_m == whole->force_law.guidance_stiffness_n_per_m);
    CHECK(recorded.force_law.acceptance == whole->force_law.acceptance);
    CHECK(recorded.spec.acceptance == whole->spec.acceptance);
    CHECK(recorded.force_law.guidance == whole->force_law.guidance);
    CHECK(recorded.force_law.paper_stiffness_n_per_m == whole->force_law.paper_stiffness_n_per_m);
    if (trial.condition == "stiff") CHECK(recorded.force_law.guidance_stiffness_n_per_m == 300.0);
    if (trial.condition == "quiz") {
      // The quiz's acceptance, not the specification's default: the condition's part reached the record.
      CHECK(recorded.force_law.acceptance.hint_after_misses == 1.0);
      CHECK(recorded.spec.acceptance.hint_after_misses == 1.0);
    }
    ++compared;
  }
  CHECK(compared == plan.size());
}

TEST_CASE(
    "a person writing is spelt person in session.json and its records, and older files' human reads as "
    "person",
    "[study][session]") {
  TempFolder temp;
  SessionSetup setup = simulated("S07");
  setup.writer = TrialWriter::person;
  SessionFolder session = SessionFolder::create(temp.path / "S07", setup, small_protocol());
  nlohmann::json document = nlohmann::json::parse(read(session.path() / "session.json"));
  CHECK(document["writer"] == "person");
  CHECK(document["version"] == 3);
  CHECK(study_detail::manifest_from_json(document.dump(2), "session.json").setup.writer ==
        TrialWriter::person);

  // Versions 1 and 2 said "human": read as "person". Version 3 refuses it as any other unknown spelling.
  document["writer"] = "human";
  CHECK_THROWS_WITH(study_detail::manifest_from_json(document.dump(2), "session.json"),
                    Catch::StartsWith("session.json: /writer: ") && Catch::Contains("\"person\""));
  document["version"] = 2;
  CHECK(study_detail::manifest_from_json(document.dump(2), "session.json").setup.writer ==
        TrialWriter::person);

  // A trial record of version 2 says "human" as well; every reader of records sees "person".
  const auto record_with = [&](int version, const char* kind) {
    const fs::path file = temp.path / ("record-" + std::to_string(version) + ".json");
    std::ofstream(file) << nlohmann::json{{"format", study_detail::kTrialRecordFormat},
                                          {"version", version},
                                          {"writer", {{"kind", kind}, {"subject", "S07"}}}}
                               .dump();
    return study_detail::read_trial_record(file)["writer"]["kind"].get<std::string>();
  };
  CHECK(record_with(2, "human") == "person");
  CHECK(record_with(3, "person") == "person");
  CHECK(record_with(3, "human") == "human");  // left for the record's reader to refuse against its session
}

TEST_CASE("session.json, written a planned trial at a time, is the JSON library's own dump of its document",
          "[study][session]") {
  // The writer never holds the plan as one JSON tree (a plan of a million trials took gigabytes): its text
  // must still be exactly what dumping the whole document gives, so that readers and SHA-256s see one format.
  TempFolder temp;
  SessionFolder first = SessionFolder::create(temp.path, simulated("J1"), small_protocol());
  const std::string text = read(SessionLayout::manifest(first.path()));
  REQUIRE(first.plan().size() == 3);
  CHECK(nlohmann::json::parse(text).dump(2) + "\n" == text);
  CHECK(study_detail::manifest_to_json(first.manifest()) == text);
  // Counted without building it: the whole text's bytes, and past a limit the trial that takes it there.
  const study_detail::ManifestSize whole = study_detail::manifest_json_bytes(first.manifest(), text.size());
  CHECK(whole.bytes == text.size());
  CHECK(whole.trials == 3);
  const std::size_t before_plan = text.find("\"plan\": [") + 9;
  const study_detail::ManifestSize cut =
      study_detail::manifest_json_bytes(first.manifest(), before_plan + 10);
  CHECK(cut.bytes > before_plan + 10);
  CHECK(cut.trials == 1);
  // An empty plan is the document as it is.
  SessionManifest empty = first.manifest();
  empty.plan.clear();
  nlohmann::json document = nlohmann::json::parse(text);
  document["plan"] = nlohmann::json::array();
  CHECK(study_detail::manifest_to_json(empty) == document.dump(2) + "\n");
}

TEST_CASE("a subject's seed rounded to a double by a tool that re-saved session.json is named, not run",
          "[study][session]") {
  TempFolder temp;
  SessionFolder session = SessionFolder::create(temp.path / "S07", simulated("S07"), small_protocol());
  nlohmann::json document = nlohmann::json::parse(read(session.path() / "session.json"));
  const std::uint64_t seed = subject_seed("S07");
  REQUIRE(seed > (std::uint64_t{1} << 53));  // else no double-reading tool could change it
  const auto rounded = static_cast<std::uint64_t>(static_cast<double>(seed));
  REQUIRE(rounded != seed);
  CHECK(study_detail::manifest_from_json(document.dump(2), "session.json").setup.writer_seed == seed);
  document["writer_seed"] = rounded;
  CHECK_THROWS_WITH(study_detail::manifest_from_json(document.dump(2), "session.json"),
                    Catch::StartsWith("session.json: /writer_seed: is " + std::to_string(rounded)) &&
                        Catch::Contains("put back " + std::to_string(seed)));
  // Another seed altogether (a session made with its own seed) is read as it is.
  document["writer_seed"] = 12345;
  CHECK(study_detail::manifest_from_json(document.dump(2), "session.json").setup.writer_seed == 12345);
}
