#include "calligraphy/study/session_reader.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/study/protocol.hpp"
#include "core/json_reader.hpp"
#include "core/whole_file.hpp"
#include "study/names.hpp"
#include "study/record_metrics.hpp"
#include "study/saved_sessions.hpp"
#include "study/trial_row.hpp"

namespace calligraphy {
namespace fs = std::filesystem;
namespace {

using nlohmann::json;

Vec2 vec2(const json_detail::JsonView& value) {
  if (!value.json().is_array() || value.size() < 2)
    json_detail::fail(value.source(), value.pointer(), "expected [x, y]");
  return {json_detail::as_number(value.json()[0], value.pointer() + "/0", value.source(), -1e6, 1e6),
          json_detail::as_number(value.json()[1], value.pointer() + "/1", value.source(), -1e6, 1e6)};
}

// The reference strokes and start points from the record's scene.
void read_scene(const json_detail::JsonView& record, ReportTrial& trial) {
  if (!record.object("scene").has("characters"))
    json_detail::fail(record.source(), "/scene", "missing (required)");
  const json_detail::JsonView characters = record.object("scene").array("characters");
  for (std::size_t c = 0; c < characters.size(); ++c) {
    const json_detail::JsonView strokes = characters.object_at(c).array("strokes");
    for (std::size_t s = 0; s < strokes.size(); ++s) {
      const json_detail::JsonView stroke = strokes.object_at(s);
      std::vector<Vec2> polyline;
      const json_detail::JsonView points = stroke.array("polyline_m");
      for (std::size_t i = 0; i < points.size(); ++i) polyline.push_back(vec2(points.at(i)));
      trial.reference_m.push_back(std::move(polyline));
      trial.stroke_starts_m.push_back(
          vec2(json_detail::JsonView(stroke.has("start_m") ? stroke.json()["start_m"] : json(),
                                     stroke.pointer() + "/start_m", stroke.source())));
    }
  }
}

// The name of the trace file a record names beside it: files.trace (HDF5), or files.csv in a record of an
// older folder (gzip or plain CSV); a plain name, never a path.
std::string trace_file_name(const json_detail::JsonView& record) {
  const json_detail::JsonView files = record.object("files");
  const char* const key = files.has("trace") ? "trace" : "csv";
  const std::string name = files.string_or(key, "");
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    json_detail::fail(record.source(), std::string("/files/") + key, "expected a file name");
  return name;
}

// The trial's trace (HDF5, trace_hdf5.hpp; or trial_csv's t,x,y,z,fx,fy,fz,state,stroke,element[,attempt,
// rewritten], gzip or plain, in older folders) through the one trace reader: times, positions, pen down,
// in-plane force. With `hash` (a record that names its trace by SHA-256) the file is read once, whole: its
// rows are parsed from the bytes that are hashed, and their SHA-256 returned. Without (an older record, whose
// trace may be a long gzip CSV) it is streamed a block at a time, as ever, and "" returned.
std::string read_trace(const fs::path& file, double paper_z_m, bool hash, ReportTrial& trial) {
  PenTraceCsvOptions options;
  options.paper_z_m = paper_z_m;
  options.read_force = true;
  options.max_file_bytes = kMaxTrialCsvBytes;
  // A study trial's trace is drawn, not scored: no limit on samples or segments beside the size's.
  options.max_samples = std::numeric_limits<std::size_t>::max();
  options.max_pen_down_segments = std::numeric_limits<std::size_t>::max();
  const auto keep = [&trial](const PenTraceRow& row) {
    trial.time_s.push_back(row.sample.time_s);
    trial.position_m.push_back(row.sample.position_m);
    trial.pen_down.push_back(row.sample.pen_down);
    trial.in_plane_force_n.push_back(row.in_plane_force_n);
  };
  if (!hash) {
    for_each_pen_trace_row(file, Placement{}, options, keep);
    return {};
  }
  const std::string bytes = read_regular_file(file, kMaxTrialCsvBytes);
  for_each_pen_trace_row_of_bytes(bytes, file.string(), Placement{}, options, keep);
  return sha256_hex(bytes);
}

// The trace beside the record is the one the record names by its SHA-256 (files.trace_sha256, written since
// traces are bound to their records; an older record names none and its trace is read as it is): a trace
// copied or renamed from another trial is refused, naming both. `actual`: the SHA-256 of the bytes read.
void check_trace_is_the_records(const json_detail::JsonView& record, const fs::path& trace,
                                const std::string& actual) {
  const json_detail::JsonView files = record.object("files");
  if (!files.has("trace_sha256")) return;
  const std::string expected = files.string_or("trace_sha256", "");
  if (actual != expected) {
    json_detail::fail(record.source(), "/files/trace_sha256",
                      "names a trace of SHA-256 " + expected + ", but " + trace.string() + " has SHA-256 " +
                          actual + ": it is not this trial's trace");
  }
}

// A record under a session's trials/ is that session's: it names the session's subject and id (the folder's
// name) and, for a simulated writer, the session's writer profile. A record copied in from another study's
// session of the same stem, or a session folder renamed (its id is its name), is refused naming the record's
// key, rather than reported under labels that are not its own.
void check_record_is_the_sessions(const json& document, const std::string& source,
                                  const SessionManifest& manifest) {
  const json_detail::JsonView record(document, "", source);
  const auto differs = [&](const char* key, const std::string& expected, const std::string& what) {
    if (!record.has(key)) return;
    const std::string named = record.string_or(key, "");
    if (named != expected) {
      json_detail::fail(source, std::string("/") + key,
                        "names " + what + " '" + named + "', but the record lies in the session folder of '" +
                            expected + "' (" + manifest.session_id +
                            "): a record copied in from another session, or the session folder renamed (its "
                            "name is its id); put it back where it was saved");
    }
  };
  differs("subject", manifest.setup.subject.id, "the subject");
  differs("session", manifest.session_id, "the session");
  const json_detail::JsonView writer = record.object("writer");
  const std::string kind = writer.string_or("kind", "");
  const std::string session_writer(enum_spelling(manifest.setup.writer));
  if (!kind.empty() && kind != session_writer) {
    json_detail::fail(source, "/writer/kind",
                      "is '" + kind + "', but the session " + manifest.session_id + " was written by a " +
                          session_writer +
                          " writer: a record copied in from another session; put it back where it was saved");
  }
  const std::string profile = writer.object("profile").string_or("name", "");
  if (kind == "simulated" && !profile.empty() && !manifest.setup.writer_profile.empty() &&
      profile != manifest.setup.writer_profile) {
    json_detail::fail(
        source, "/writer/profile/name",
        "is '" + profile + "', but the session " + manifest.session_id + " ran the simulated writer '" +
            manifest.setup.writer_profile +
            "': a record copied in from another study's session; put it back where it was saved");
  }
}

// A record under a session's trials/ is the trial of the plan its file name gives: its own plan entry
// (`trial`: index and file stem) and characters are that trial's. A record copied over another trial's of
// the same session (its trace too, so that the checksums agree) is refused naming the record's key, rather
// than reported with one character's strokes under another's label.
void check_record_is_the_plans(const json& document, const std::string& source, const PlannedTrial& plan) {
  const json_detail::JsonView record(document, "", source);
  const std::string stem = SessionFolder::trial_stem(plan);
  const auto copied = [&](const std::string& pointer, const std::string& named, const std::string& planned) {
    json_detail::fail(source, pointer,
                      "is " + named + ", but the record is saved as " + stem + ", trial " +
                          std::to_string(plan.index + 1) + " of the session's plan (" + planned +
                          "): a record copied from another trial; put it back where it was saved");
  };
  std::string characters;
  for (const char32_t c : plan.characters) characters += encode_utf8(c);
  if (record.has("characters")) {
    const std::string named = record.string_or("characters", "");
    if (named != characters) copied("/characters", "'" + named + "'", "characters '" + characters + "'");
  }
  // Its labels too: a record of one condition edited to another's would be read under the plan's condition
  // with the other's mode and values.
  const std::string phase = to_string(plan.phase);
  const auto same_labels = [&](const json_detail::JsonView& view, const std::string& at) {
    if (view.has("condition")) {
      const std::string named = view.string_or("condition", "");
      if (named != plan.condition)
        copied(at + "/condition", "'" + named + "'", "condition '" + plan.condition + "'");
    }
    if (view.has("phase")) {
      const std::string named = view.string_or("phase", "");
      if (named != phase) copied(at + "/phase", "'" + named + "'", "phase '" + phase + "'");
    }
    if (view.has("repetition")) {
      const std::int64_t repetition = view.integer_or("repetition", 0, 0, std::int64_t{1} << 40);
      if (repetition != plan.repetition)
        copied(at + "/repetition", std::to_string(repetition),
               "repetition " + std::to_string(plan.repetition));
    }
  };
  if (!record.has("trial")) {
    same_labels(record, "");
    return;
  }
  const json_detail::JsonView trial = record.object("trial");
  if (trial.has("index")) {
    const std::int64_t index = trial.integer_or("index", 0, 0, std::int64_t{1} << 40);
    if (index != static_cast<std::int64_t>(plan.index) + 1)
      copied("/trial/index", std::to_string(index), "index " + std::to_string(plan.index + 1));
  }
  if (trial.has("file")) {
    const std::string file = trial.string_or("file", "");
    if (file != stem) copied("/trial/file", "'" + file + "'", "file '" + stem + "'");
  }
  // After the plan entry: a record copied over another trial is named by its index first.
  same_labels(record, "");
  same_labels(trial, "/trial");
}

// The saved record `json_file` of the session's trial `plan`, read and checked to be that trial's: its
// session's (check_record_is_the_sessions) and its plan's (check_record_is_the_plans).
json read_sessions_record(const fs::path& json_file, const SessionManifest& manifest,
                          const PlannedTrial& plan) {
  json document = study_detail::read_trial_record(json_file);
  check_record_is_the_sessions(document, json_file.string(), manifest);
  check_record_is_the_plans(document, json_file.string(), plan);
  const json_detail::JsonView record(document, "", json_file.string());
  // A record bound to its trace (files.trace_sha256) names its own: the trace beside it of its own stem, so
  // that another trial's trace, hashed right, is not drawn and analysed under this trial's labels.
  if (record.object("files").has("trace") && record.object("files").has("trace_sha256")) {
    const std::string own = SessionFolder::trial_stem(plan) + ".trace.h5";
    const std::string named = trace_file_name(record);
    if (named != own) {
      json_detail::fail(json_file.string(), "/files/trace",
                        "names the trace '" + named + "', another trial's: this trial's is '" + own +
                            "'; put the record back as it was saved");
    }
  }
  // Its mode is its condition's in the session's protocol copy: the tables' `mode` column is read from it.
  for (const StudyCondition& condition : manifest.protocol.protocol.conditions) {
    if (condition.name != plan.condition || !record.has("mode")) continue;
    const std::string mode = to_string(condition_mode(condition));
    const std::string named = record.string_or("mode", "");
    if (named != mode) {
      json_detail::fail(json_file.string(), "/mode",
                        "is '" + named + "', but the condition " + plan.condition +
                            " of the session's protocol is '" + mode +
                            "': a record edited or copied from another trial; put it back as it was saved");
    }
  }
  return document;
}

// The tidy tables' rows of the saved trial whose record `document` was read from `json_file`: the one
// reading of a record into rows, for the tables alone and beside the pages.
void append_trial_rows(const json& document, const fs::path& json_file, const SessionManifest& manifest,
                       const PlannedTrial& plan, StudyTables& rows) {
  const std::string source = json_file.string();
  TrialRow row = study_detail::trial_row(document, source, manifest, plan, rows.strokes);
  const json_detail::JsonView record(document, "", source);
  row.trace_file = json_file.parent_path() / trace_file_name(record);
  row.trace_sha256 = record.object("files").string_or("trace_sha256", "");
  rows.trials.push_back(std::move(row));
}

ReportTrial read_trial(const fs::path& json_file, const SessionManifest& manifest, const PlannedTrial& plan,
                       StudyTables* rows) {
  const std::string source = json_file.string();
  const json document = read_sessions_record(json_file, manifest, plan);
  const json_detail::JsonView record(document, "", source);
  // the tidy tables' rows from the same parse of the record
  if (rows != nullptr) append_trial_rows(document, json_file, manifest, plan, *rows);
  ReportTrial trial;
  trial.subject = manifest.setup.subject.id;
  trial.session = manifest.session_id;
  trial.phase = to_string(plan.phase);
  trial.condition = plan.condition;
  trial.mode = record.string_or("mode", "");
  for (const char32_t c : plan.characters) trial.characters += encode_utf8(c);
  trial.end_reason = record.string_or("end_reason", "");
  trial.index = plan.index + 1;
  trial.block = plan.block + 1;
  trial.item = plan.item + 1;
  trial.repetition = plan.repetition;
  // null for a trial in which no stroke was written (the time ran out first): shown as such, not refused
  trial.time_total_s = study_detail::record_metric(record, "total_time_s").value_or(std::nan(""));
  trial.mean_deviation_m = study_detail::record_metric(record, "mean_deviation_m").value_or(std::nan(""));
  trial.frechet_m = study_detail::record_metric(record, "frechet_m");
  trial.dtw_m = study_detail::record_metric(record, "dtw_m");
  trial.order_errors = static_cast<std::size_t>(record.number("order_errors", 0.0, 1e12));
  trial.backwards_strokes = static_cast<std::size_t>(record.number("backwards_strokes", 0.0, 1e12));
  trial.completed = trial.end_reason == "completed";
  if (record.has("quiz")) {
    const json_detail::JsonView quiz = record.object("quiz");
    trial.quiz_misses = static_cast<int>(quiz.integer_or("misses", 0, 0, 1 << 30));
    // Absent before the quiz credited strokes assisted: none were.
    trial.quiz_assisted = static_cast<int>(quiz.integer_or("strokes_assisted", 0, 0, 1 << 30));
  }
  read_scene(record, trial);
  const json_detail::JsonView per_stroke = record.array("per_stroke");
  for (std::size_t i = 0; i < per_stroke.size(); ++i) {
    const json_detail::JsonView stroke = per_stroke.object_at(i);
    const std::optional<double> start_s = stroke.optional_number("start_s", -1e12, 1e12);
    const std::optional<double> end_s = stroke.optional_number("end_s", -1e12, 1e12);
    if (!start_s || !end_s) continue;  // a stroke never written
    trial.strokes.push_back({i, *start_s, *end_s, stroke.boolean_or("completed", false)});
  }
  const double paper_z = record.object("scene").object("layout").number_or("paper_z_m", 0.0, -1e6, 1e6);
  const std::string trace = trace_file_name(record);
  const bool bound = record.object("files").has("trace_sha256");
  std::string sha256;
  try {
    sha256 = read_trace(json_file.parent_path() / trace, paper_z, bound, trial);
  } catch (const DataError& e) {  // the record names the trace: it is the record that is at fault
    json_detail::fail(source, record.object("files").has("trace") ? "/files/trace" : "/files/csv",
                      "names the trace '" + trace + "', which cannot be read: " + e.what());
  }
  // read whole and not damaged: is it another trial's?
  if (bound) check_trace_is_the_records(record, json_file.parent_path() / trace, sha256);
  return trial;
}

std::string session_line(const SessionManifest& m, const fs::path& folder, std::size_t saved) {
  const std::string writer = m.setup.writer == TrialWriter::simulated
                                 ? "simulated writer (" + m.setup.writer_profile + ", learning " +
                                       std::string(enum_spelling(m.setup.writer_learning)) + ")"
                                 : "person";
  return folder.string() + ", protocol " + m.protocol.protocol.name + " (sha256 " +
         m.protocol.sha256.substr(0, 12) + "), session " + std::to_string(m.setup.session_number) +
         ", device " + m.setup.device + ", " + writer + ", " + std::to_string(saved) + " of " +
         std::to_string(m.plan.size()) + " trials saved, library " + m.library.version + " " +
         m.library.build_type;
}

fs::path trial_record_file(const fs::path& folder, const PlannedTrial& plan) {
  return SessionLayout::record(folder, plan);
}

bool is_saved(const fs::path& folder, const PlannedTrial& plan) {
  std::error_code error;
  return fs::exists(trial_record_file(folder, plan), error);
}

// What the simulated subjects were, from the learning models their sessions ran with.
std::string simulated_note(const std::set<std::string>& learning) {
  std::string note =
      "Simulated subjects: a simulated writer (hand impedance, minimum-jerk strokes, a seeded bias and "
      "tremor) moves a simulated device; it is a model of a writer, not a person.";
  if (learning.contains("two-state")) {
    note +=
        " With writer learning two-state it learns: a memory of each typical stroke and character that "
        "practice builds and time between sessions thins (docs/writer.md).";
  }
  if (learning.contains("none")) {
    note += " With writer learning none it does not learn: its repetitions differ only by their seeds.";
  }
  return note;
}

}  // namespace

StudyReportSessions list_report_sessions(const std::vector<fs::path>& roots) {
  const std::vector<fs::path> folders = study_detail::session_folders_under(roots);
  study_detail::DistinctSessions distinct;
  StudyReportSessions found;
  std::set<std::string> protocols, protocol_names, learning;
  // The first session of each protocol name, and its protocol.
  std::map<std::string, std::pair<fs::path, LoadedProtocol>> by_name;
  // Each subject's session of each number of each protocol, so that a session run twice (two folders of one
  // subject's session 1) is refused rather than pooled as one subject's trials.
  std::map<std::string, fs::path> by_session;
  // Each study folder's identity (ROOT of ROOT/SUBJECT/SESSION): a session copied in from another study
  // folder is not pooled with this study's.
  std::map<fs::path, std::optional<std::string>> studies;
  for (const fs::path& folder : folders) {
    SessionManifest manifest = study_detail::read_session_manifest(folder);
    if (!distinct.add(folder, manifest)) continue;
    // The study folder the session lies in, by its own name (a session given as `.` or through a link).
    const fs::path root = study_detail::named_folder(folder).parent_path().parent_path();
    auto study = studies.find(root);
    if (study == studies.end()) study = studies.emplace(root, StudyIdentity::read(root)).first;
    const std::optional<std::string>& study_id = study->second;
    StudyIdentity::check(study_id, root, folder, manifest);
    // The trainer's free practice saves a session 1 on every run: those are not one design's sessions.
    if (manifest.protocol.path != "calligraphy-train") {
      const std::string key = manifest.setup.subject.id + '\n' + manifest.protocol.protocol.name + '\n' +
                              std::to_string(manifest.setup.session_number);
      const auto [other, first_time] = by_session.try_emplace(key, folder);
      if (!first_time) {
        throw DataError("subject " + manifest.setup.subject.id + " has session " +
                        std::to_string(manifest.setup.session_number) + " of protocol '" +
                        manifest.protocol.protocol.name + "' twice, in " + other->second.string() + " and " +
                        folder.string() +
                        " (the session was run twice): its trials would be pooled as one session; move one "
                        "of the folders "
                        "out of the study folder, or read each on its own");
      }
    }
    // Sessions are grouped by protocol name (the tables' `protocol`): two protocols under one name would be
    // pooled as one design, a wrong result rather than a warning.
    const auto [first, inserted] =
        by_name.try_emplace(manifest.protocol.protocol.name, folder, manifest.protocol);
    if (!inserted && study_detail::protocols_conflict(first->second.second, manifest.protocol)) {
      json_detail::fail(
          SessionLayout::manifest(folder).string(), "/protocol/sha256",
          "protocol '" + manifest.protocol.protocol.name + "' here has SHA-256 " + manifest.protocol.sha256 +
              ", but in " + SessionLayout::manifest(first->second.first).string() + " SHA-256 " +
              first->second.second.sha256 +
              ": two different protocols under one name would be pooled as one design; read them "
              "apart (report each study folder on its own)");
    }
    protocols.insert(manifest.protocol.sha256);
    protocol_names.insert(manifest.protocol.protocol.name);
    if (manifest.setup.writer == TrialWriter::simulated)
      learning.insert(std::string(enum_spelling(manifest.setup.writer_learning)));
    ReportSession shown;
    shown.subject = manifest.setup.subject.id;
    shown.session = manifest.session_id;
    shown.group = manifest.group;
    shown.planned = manifest.plan.size();
    for (const PlannedTrial& plan : manifest.plan) shown.saved += is_saved(folder, plan) ? 1 : 0;
    shown.description = session_line(manifest, folder, shown.saved);
    for (const StudyCondition& condition : manifest.protocol.protocol.conditions)
      shown.conditions.push_back(condition.name);
    found.index.sessions.push_back(shown);
    found.sessions.push_back({std::move(shown), folder, std::move(manifest)});
  }
  std::string names;
  for (const std::string& name : protocol_names) names += (names.empty() ? "" : ", ") + name;
  found.index.title = "Trials of " + names;
  if (protocols.size() > 1) {
    found.index.notes.push_back("The sessions ran under " + std::to_string(protocols.size()) +
                                " different protocol files.");
  }
  if (!learning.empty()) found.index.notes.push_back(simulated_note(learning));
  return found;
}

void read_session_trials(const ReportedSession& session, const std::function<void(const ReportTrial&)>& trial,
                         StudyTables* rows) {
  for (const PlannedTrial& plan : session.manifest.plan) {
    if (!is_saved(session.folder, plan)) continue;  // not saved (yet): a running session can be reported
    trial(read_trial(trial_record_file(session.folder, plan), session.manifest, plan, rows));
  }
}

void read_session_rows(const ReportedSession& session, StudyTables& rows) {
  for (const PlannedTrial& plan : session.manifest.plan) {
    if (!is_saved(session.folder, plan)) continue;  // not saved (yet): a running session can be read
    const fs::path json_file = trial_record_file(session.folder, plan);
    const json document = read_sessions_record(json_file, session.manifest, plan);
    append_trial_rows(document, json_file, session.manifest, plan, rows);
  }
}

}  // namespace calligraphy
