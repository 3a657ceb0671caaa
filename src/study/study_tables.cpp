#include "calligraphy/study/study_tables.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "core/unicode.hpp"
#include "study/json_reader.hpp"
#include "study/names.hpp"
#include "study/saved_sessions.hpp"
#include "study/trial_row.hpp"

namespace calligraphy {
namespace fs = std::filesystem;
namespace {

using nlohmann::json;
using study_detail::fail;

// A record's number; absent when missing or null.
std::optional<double> optional_number(const json& object, const char* key, const std::string& source,
                                      const std::string& pointer) {
  const auto found = object.find(key);
  if (found == object.end() || found->is_null()) return std::nullopt;
  return study_detail::as_number(*found, pointer + "/" + key, source, -1e12, 1e12);
}

// A record's length in mm as metres; absent when missing or null.
std::optional<double> metres(const json& object, const char* key_mm, const std::string& source,
                             const std::string& pointer) {
  const std::optional<double> millimetres = optional_number(object, key_mm, source, pointer);
  return millimetres ? std::optional<double>(*millimetres * 1e-3) : std::nullopt;
}

double number(const json& object, const char* key, const std::string& source, const std::string& pointer) {
  const auto found = object.find(key);
  if (found == object.end()) fail(source, pointer + "/" + key, "missing (required)");
  return study_detail::as_number(*found, pointer + "/" + key, source, -1e12, 1e12);
}

std::size_t count(const json& object, const char* key, const std::string& source,
                  const std::string& pointer) {
  const auto found = object.find(key);
  if (found == object.end()) fail(source, pointer + "/" + key, "missing (required)");
  return static_cast<std::size_t>(
      study_detail::as_integer(*found, pointer + "/" + key, source, 0, 1LL << 40));
}

// The strokes of one character of a record: its per-stroke metrics and the verdicts of the segments the
// matcher gave each stroke.
void add_strokes(const json& character, std::size_t index, const std::string& source, const TrialRow& trial,
                 std::vector<StrokeRow>& strokes) {
  const std::string at = "/per_character/" + std::to_string(index);
  const json& per_stroke = character.value("per_stroke", json::array());
  const std::size_t first = strokes.size();
  for (std::size_t s = 0; s < per_stroke.size(); ++s) {
    const json& metrics = per_stroke[s];
    const std::string pointer = at + "/per_stroke/" + std::to_string(s);
    StrokeRow row;
    row.subject = trial.subject;
    row.session = trial.session;
    row.trial = trial.trial;
    row.phase = trial.phase;
    row.condition = trial.condition;
    row.character = index;
    row.character_text = character.value("character", "");
    row.stroke = s;
    row.typical_id = static_cast<int>(study_detail::as_integer(metrics.value("typical_id", json(0)),
                                                               pointer + "/typical_id", source, 0, 39));
    row.written = metrics.value("written", false);
    row.backwards = metrics.value("backwards", false);
    row.mean_deviation_m = metres(metrics, "mean_deviation_mm", source, pointer);
    row.max_deviation_m = metres(metrics, "max_deviation_mm", source, pointer);
    row.rms_deviation_m = metres(metrics, "rms_deviation_mm", source, pointer);
    row.frechet_m = metres(metrics, "frechet_mm", source, pointer);
    row.dtw_m = metres(metrics, "dtw_mm", source, pointer);
    row.path_length_m = metres(metrics, "path_length_mm", source, pointer);
    row.time_s = optional_number(metrics, "time_s", source, pointer);
    strokes.push_back(std::move(row));
  }
  const json& segments = character.value("segments", json::array());
  for (const json& segment : segments) {
    const json& verdict = segment.value("verdict", json());
    if (!verdict.is_object()) continue;  // an ignored segment (a dot, a touch) has no verdict
    // The stroke the segment was written for: the one it matched, else the one expected then.
    const json& stroke = verdict.value("matched_stroke", json()).is_number()
                             ? verdict["matched_stroke"]
                             : verdict.value("expected_stroke", json());
    if (!stroke.is_number_unsigned() || stroke.get<std::size_t>() >= per_stroke.size()) continue;
    StrokeRow& row = strokes[first + stroke.get<std::size_t>()];
    ++row.segments;
    if (!verdict.value("accepted", false)) {
      ++row.refused_segments;
      row.refusal = verdict.value("refusal", "");
    }
  }
}

TrialRow read_trial_row(const fs::path& json_file, const SessionManifest& manifest, const PlannedTrial& plan,
                        std::vector<StrokeRow>& strokes) {
  const std::string source = json_file.string();
  const json record = study_detail::read_trial_record(json_file);
  TrialRow row = study_detail::trial_row(record, source, manifest, plan, strokes);
  const std::string csv = record.value("files", json::object()).value("csv", "");
  if (csv.empty() || csv.find('/') != std::string::npos) fail(source, "/files/csv", "expected a file name");
  row.trace_file = json_file.parent_path() / csv;
  return row;
}

}  // namespace

TrialRow study_detail::trial_row(const json& record, const std::string& source,
                                 const SessionManifest& manifest, const PlannedTrial& plan,
                                 std::vector<StrokeRow>& strokes) {
  TrialRow row;
  row.subject = manifest.setup.subject.id;
  row.session = manifest.session_id;
  row.protocol = manifest.protocol.protocol.name;
  row.session_number = manifest.setup.session_number;
  row.group = manifest.group;
  row.phase = to_string(plan.phase);
  row.block = plan.block;
  row.condition = plan.condition;
  row.mode = record.value("mode", "");
  for (const char32_t c : plan.characters) row.characters += encode_utf8(c);
  row.trial = plan.index;
  row.item = plan.item;
  row.repetition = static_cast<std::size_t>(plan.repetition - 1);
  row.writer = manifest.setup.writer;
  row.end_reason = record.value("end_reason", "");
  row.start_utc = record.value("start_time_utc", "");
  row.completed_in_order = record.value("completed_in_order", false);
  row.strokes_total = count(record, "strokes_total", source, "");
  row.strokes_written = count(record, "strokes_written", source, "");
  row.strokes_accepted = count(record, "strokes_accepted", source, "");
  row.order_errors = count(record, "order_errors", source, "");
  row.backwards_strokes = count(record, "backwards_strokes", source, "");
  row.unmatched_segments = count(record, "unmatched_segments", source, "");
  row.mean_deviation_m = metres(record, "mean_deviation_mm", source, "");
  row.max_deviation_m = metres(record, "max_deviation_mm", source, "");
  row.rms_deviation_m = metres(record, "rms_deviation_mm", source, "");
  row.frechet_m = metres(record, "frechet_mm", source, "");
  row.dtw_m = metres(record, "dtw_mm", source, "");
  row.total_time_s = number(record, "total_time_s", source, "");
  row.pen_down_time_s = number(record, "pen_down_time_s", source, "");
  row.velocity_peaks = static_cast<int>(count(record, "velocity_peaks", source, ""));
  row.normalised_jerk = optional_number(record, "normalised_jerk", source, "");
  const json& memory = record.value("writer", json::object()).value("memory", json::object());
  row.shape_skill = optional_number(memory, "shape_skill", source, "/writer/memory");
  row.order_skill = optional_number(memory, "order_skill", source, "/writer/memory");
  row.timing_skill = optional_number(memory, "timing_skill", source, "/writer/memory");
  const json& characters = record.value("per_character", json::array());
  for (std::size_t c = 0; c < characters.size(); ++c) add_strokes(characters[c], c, source, row, strokes);
  return row;
}

namespace {

// One CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

std::string field(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::string field(const std::optional<double>& value) { return value ? field(*value) : std::string(); }
std::string field(std::size_t value) { return std::to_string(value); }
std::string field(int value) { return std::to_string(value); }
std::string field(bool value) { return value ? "true" : "false"; }

template <typename... Fields>
void line(std::string& out, const Fields&... fields) {
  bool first = true;
  ((out += (first ? "" : ","), out += field(fields), first = false), ...);
  out += '\n';
}

}  // namespace

StudyTables read_study_tables(const std::vector<fs::path>& roots) {
  const std::vector<fs::path> folders = study_detail::session_folders_under(roots);
  StudyTables tables;
  for (const fs::path& folder : folders) {
    const SessionManifest manifest = study_detail::read_session_manifest(folder);
    for (const PlannedTrial& plan : manifest.plan) {
      const fs::path json_file = folder / "trials" / (SessionFolder::trial_stem(plan) + ".json");
      std::error_code error;
      if (!fs::exists(json_file, error)) continue;  // not saved (yet): a running session can be read
      tables.trials.push_back(read_trial_row(json_file, manifest, plan, tables.strokes));
    }
  }
  return tables;
}

std::string trials_csv(const StudyTables& tables) {
  std::string out =
      "subject,session,protocol,session_number,group,phase,block,condition,mode,characters,trial,item,"
      "repetition,writer,end_reason,"
      "start_utc,completed_in_order,strokes_total,strokes_written,strokes_accepted,order_errors,"
      "backwards_strokes,unmatched_segments,mean_deviation_m,max_deviation_m,rms_deviation_m,frechet_m,dtw_m,"
      "total_time_s,pen_down_time_s,velocity_peaks,normalised_jerk,shape_skill,order_skill,timing_skill,"
      "trace_file\n";
  for (const TrialRow& r : tables.trials) {
    line(out, r.subject, r.session, r.protocol, r.session_number, r.group, r.phase, r.block, r.condition,
         r.mode, r.characters, r.trial, r.item, r.repetition, r.writer, r.end_reason, r.start_utc,
         r.completed_in_order, r.strokes_total, r.strokes_written, r.strokes_accepted, r.order_errors,
         r.backwards_strokes, r.unmatched_segments, r.mean_deviation_m, r.max_deviation_m, r.rms_deviation_m,
         r.frechet_m, r.dtw_m, r.total_time_s, r.pen_down_time_s, r.velocity_peaks, r.normalised_jerk,
         r.shape_skill, r.order_skill, r.timing_skill, r.trace_file.string());
  }
  return out;
}

std::string strokes_csv(const StudyTables& tables) {
  std::string out =
      "subject,session,trial,phase,condition,character,character_text,stroke,typical_id,written,backwards,"
      "segments,refused_segments,refusal,mean_deviation_m,max_deviation_m,rms_deviation_m,frechet_m,dtw_m,"
      "time_s,path_length_m\n";
  for (const StrokeRow& r : tables.strokes) {
    line(out, r.subject, r.session, r.trial, r.phase, r.condition, r.character, r.character_text, r.stroke,
         r.typical_id, r.written, r.backwards, r.segments, r.refused_segments, r.refusal, r.mean_deviation_m,
         r.max_deviation_m, r.rms_deviation_m, r.frechet_m, r.dtw_m, r.time_s, r.path_length_m);
  }
  return out;
}

}  // namespace calligraphy
