#include "calligraphy/study/study_tables.hpp"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <nlohmann/json.hpp>
#include <type_traits>
#include <variant>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/core/worker_threads.hpp"
#include "calligraphy/study/session_reader.hpp"
#include "core/json_reader.hpp"
#include "study/names.hpp"
#include "study/record_metrics.hpp"
#include "study/trial_row.hpp"

namespace calligraphy {
namespace fs = std::filesystem;
namespace {

using nlohmann::json;

using study_detail::record_metric;

// A metric's value in `object` (a record or one of its strokes) as its kind is: a number in the metric's
// unit (read under its legacy name too), a count, a flag. Missing, it is what the metric table says: null, 0
// (false), or a DataError naming the file and key.
MetricValue record_value(const json_detail::JsonView& object, const MetricInfo& info) {
  if (!study_detail::contains_metric(object, info)) {
    switch (info.if_missing) {
      case MetricMissing::refused:
        json_detail::fail(object.source(), object.pointer() + "/" + std::string(info.name),
                          "missing (required)");
      case MetricMissing::zero:
        if (info.kind == MetricKind::flag) return MetricValue(false);
        return info.kind == MetricKind::count ? MetricValue(std::int64_t{0}) : MetricValue(0.0);
      case MetricMissing::null:
        break;
    }
    return MetricValue(std::monostate{});
  }
  switch (info.kind) {
    case MetricKind::count:
      return MetricValue(object.integer_or(std::string(info.name), 0, 0, 1LL << 40));
    case MetricKind::flag:
      return MetricValue(object.boolean_or(std::string(info.name), false));
    case MetricKind::number:
      break;
  }
  const std::optional<double> value = record_metric(object, info);
  return value ? MetricValue(*value) : MetricValue(std::monostate{});
}

// The metric columns of `which` in `metrics`, read from `object`.
MetricValues metric_values(const json_detail::JsonView& object, StudyTable which,
                           std::span<const MetricInfo> metrics) {
  MetricValues values(which, metrics);
  for (const MetricInfo& info : study_metric_columns(which, metrics))
    values.set(info.name, record_value(object, info));
  return values;
}

void add_strokes(const json_detail::JsonView& character, std::size_t index, const TrialRow& trial,
                 std::span<const MetricInfo> metrics, std::vector<StrokeRow>& strokes) {
  const json_detail::JsonView per_stroke = character.array("per_stroke");
  const std::size_t first = strokes.size();
  for (std::size_t s = 0; s < per_stroke.size(); ++s) {
    const json_detail::JsonView stroke = per_stroke.object_at(s);
    StrokeRow row;
    row.subject = trial.subject;
    row.session = trial.session;
    row.trial = trial.trial;
    row.phase = trial.phase;
    row.condition = trial.condition;
    row.character = index + 1;
    row.character_text = character.string_or("character", "");
    row.stroke = s + 1;
    row.typical_id = static_cast<int>(stroke.integer_or("typical_id", 0, 0, 39));
    row.written = stroke.boolean_or("written", false);
    row.backwards = stroke.boolean_or("backwards", false);
    row.metrics = metric_values(stroke, StudyTable::strokes, metrics);
    strokes.push_back(std::move(row));
  }
  const json_detail::JsonView segments = character.array("segments");
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const json_detail::JsonView verdict = segments.object_at(i).object("verdict");
    if (verdict.json().empty()) continue;  // an ignored segment (a dot, a touch) has no verdict
    // The stroke the segment was written for: the one it matched, else the one expected then.
    const char* key = verdict.has("matched_stroke") ? "matched_stroke" : "expected_stroke";
    const std::int64_t stroke = verdict.integer_or(key, -1, -1, 1LL << 40);
    if (stroke < 0 || static_cast<std::size_t>(stroke) >= per_stroke.size()) continue;
    StrokeRow& row = strokes[first + static_cast<std::size_t>(stroke)];
    ++row.segments;
    if (!verdict.boolean_or("accepted", false)) {
      ++row.refused_segments;
      row.refusal = verdict.string_or("refusal", "");
    }
  }
}

}  // namespace

TrialRow study_detail::trial_row(const json& document, const std::string& source,
                                 const SessionManifest& manifest, const PlannedTrial& plan,
                                 std::vector<StrokeRow>& strokes, std::span<const MetricInfo> metrics) {
  const json_detail::JsonView record(document, "", source);
  TrialRow row;
  row.subject = manifest.setup.subject.id;
  row.session = manifest.session_id;
  row.protocol = manifest.protocol.protocol.name;
  row.session_number = manifest.setup.session_number;
  row.group = manifest.group;
  row.phase = to_string(plan.phase);
  row.block = plan.block + 1;
  row.condition = plan.condition;
  row.mode = record.string_or("mode", "");
  for (const char32_t c : plan.characters) row.characters += encode_utf8(c);
  // Design ordinals count from 1, as the trial files (001-..., r1) and session numbers do.
  row.trial = plan.index + 1;
  row.item = plan.item + 1;
  row.repetition = static_cast<std::size_t>(plan.repetition);
  row.item_set = plan.item_set;
  row.sequence = plan.sequence;
  if (plan.period > 0) row.period = plan.period;
  row.trained_condition = plan.trained_condition;
  row.writer = enum_spelling(manifest.setup.writer);
  if (manifest.setup.writer == TrialWriter::simulated) {
    row.writer_profile = manifest.setup.writer_profile;
    row.writer_learning = enum_spelling(manifest.setup.writer_learning);
  }
  row.end_reason = record.string_or("end_reason", "");
  row.start_utc = record.string_or("start_time_utc", "");
  row.metrics = metric_values(record, StudyTable::trials, metrics);
  const json_detail::JsonView memory = record.object("writer").object("memory");
  row.shape_skill = memory.optional_number("shape_skill", -1e12, 1e12);
  row.order_skill = memory.optional_number("order_skill", -1e12, 1e12);
  row.timing_skill = memory.optional_number("timing_skill", -1e12, 1e12);
  const json_detail::JsonView traits = record.object("writer").object("subject_traits");
  row.subject_writing_speed_factor = traits.optional_number("writing_speed_factor", 0.0, 1e6);
  row.subject_spatial_error_factor = traits.optional_number("spatial_error_factor", 0.0, 1e6);
  row.subject_error_rate_factor = traits.optional_number("error_rate_factor", 0.0, 1e6);
  row.subject_motor_noise_factor = traits.optional_number("motor_noise_factor", 0.0, 1e6);
  row.subject_fast_learning_per_trial = traits.optional_number("fast_learning_per_trial", 0.0, 1.0);
  row.subject_slow_learning_per_trial = traits.optional_number("slow_learning_per_trial", 0.0, 1.0);
  row.subject_fast_retention_per_trial = traits.optional_number("fast_retention_per_trial", 0.0, 1.0);
  row.subject_slow_retention_per_trial = traits.optional_number("slow_retention_per_trial", 0.0, 1.0);
  row.strokes_given_up = record.object("writer").object("log").optional_number("strokes_given_up", 0.0, 1e9);
  const json_detail::JsonView legibility = record.object("legibility");
  row.legibility_top1 = legibility.optional_number("top1", 0.0, 1.0);
  row.legibility_top5 = legibility.optional_number("top5", 0.0, 1.0);
  const json_detail::JsonView characters = record.array("per_character");
  for (std::size_t c = 0; c < characters.size(); ++c)
    add_strokes(characters.object_at(c), c, row, metrics, strokes);
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

// printf's %.17g in the C locale whatever the process's locale is: a Python program that called
// locale.setlocale(LC_ALL, "de_DE.UTF-8") would otherwise get decimal commas inside comma-separated fields.
std::string field(double value) {
  char text[32];
  return std::string(text,
                     std::to_chars(text, text + sizeof text, value, std::chars_format::general, 17).ptr);
}

std::string field(const std::optional<double>& value) { return value ? field(*value) : std::string(); }
std::string field(const std::optional<int>& value) { return value ? std::to_string(*value) : std::string(); }
std::string field(std::size_t value) { return std::to_string(value); }
std::string field(int value) { return std::to_string(value); }
// A flag as R's logical literals, which R's read.csv reads as logical and pandas' read_csv as bool (R reads
// "true"/"false" as text).
std::string field(bool value) { return value ? "TRUE" : "FALSE"; }
std::string field(std::int64_t value) { return std::to_string(value); }

// A metric's value as the field of its kind: a number as a double, a count, a flag; empty when null.
std::string field(const MetricValue& value) {
  return std::visit(
      [](const auto& v) {
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::monostate>)
          return std::string();
        else
          return field(v);
      },
      value);
}

// The fields after a first, each after a comma.
template <typename... Fields>
void fields(std::string& out, const Fields&... values) {
  ((out += ',', out += field(values)), ...);
}

// The metric columns of a row, each after a comma, in the order of `columns`.
void metric_fields(std::string& out, const MetricValues& values, const std::vector<MetricInfo>& columns) {
  for (const MetricInfo& info : columns) {
    out += ',';
    out += field(values.at(info.name));
  }
}

// The header's metric columns, each after a comma.
std::string metric_header(const std::vector<MetricInfo>& columns) {
  std::string out;
  for (const MetricInfo& info : columns) {
    out += ',';
    out.append(info.name);
  }
  return out;
}

}  // namespace

StudyTables read_study_tables(const std::vector<fs::path>& roots, unsigned threads) {
  // The folders read by the one reader of sessions, its records only: sessions in turn on `threads` threads,
  // each into its own rows, joined in the sessions' order.
  const std::vector<ReportedSession> sessions = list_report_sessions(roots).sessions;
  std::vector<StudyTables> rows(sessions.size());
  // An error names the first session in order that failed, as reading them in turn would.
  for_each_item(sessions.size(), threads, [&](std::size_t i) { read_session_rows(sessions[i], rows[i]); });
  StudyTables tables;
  for (StudyTables& session : rows) {
    std::move(session.trials.begin(), session.trials.end(), std::back_inserter(tables.trials));
    std::move(session.strokes.begin(), session.strokes.end(), std::back_inserter(tables.strokes));
    session = StudyTables{};
  }
  return tables;
}

std::string trials_csv(const StudyTables& tables, std::span<const MetricInfo> metrics) {
  const std::vector<MetricInfo> columns = study_metric_columns(StudyTable::trials, metrics);
  std::string out =
      "subject,session,protocol,session_number,group,phase,block,condition,mode,characters,trial,item,"
      "repetition,item_set,sequence,period,trained_condition,writer,writer_profile,writer_learning,end_"
      "reason,start_utc";
  out += metric_header(columns);
  out +=
      ",shape_skill,order_skill,timing_skill,subject_writing_speed_factor,subject_spatial_error_factor,"
      "subject_error_rate_factor,subject_motor_noise_factor,subject_fast_learning_per_trial,subject_slow_"
      "learning_per_trial,subject_fast_retention_per_trial,subject_slow_retention_per_trial,strokes_given_"
      "up,legibility_top1,legibility_top5,trace_file,trace_sha256\n";
  for (const TrialRow& r : tables.trials) {
    // The tables are UTF-8 text (R, pandas and Python's strings read them so): a folder given by a path with
    // a byte that is not UTF-8 is named (as printable text, which Python's message can hold too), not written
    // into them as a column no reader can decode. Only the text is refused: the rows in memory (curriculum's)
    // need no path.
    try {
      decode_utf8(r.trace_file.string());
    } catch (const InvalidArgument& error) {
      throw DataError(printable_one_line(r.trace_file.string()) +
                      ": the trace's path cannot go into the tables, which are UTF-8 text: " + error.what() +
                      "; give the study folder by a path in UTF-8 (a relative one, or rename it)");
    }
    out += field(r.subject);
    fields(out, r.session, r.protocol, r.session_number, r.group, r.phase, r.block, r.condition, r.mode,
           r.characters, r.trial, r.item, r.repetition, r.item_set, r.sequence, r.period, r.trained_condition,
           r.writer, r.writer_profile, r.writer_learning, r.end_reason, r.start_utc);
    metric_fields(out, r.metrics, columns);
    fields(out, r.shape_skill, r.order_skill, r.timing_skill, r.subject_writing_speed_factor,
           r.subject_spatial_error_factor, r.subject_error_rate_factor, r.subject_motor_noise_factor,
           r.subject_fast_learning_per_trial, r.subject_slow_learning_per_trial,
           r.subject_fast_retention_per_trial, r.subject_slow_retention_per_trial, r.strokes_given_up,
           r.legibility_top1, r.legibility_top5, r.trace_file.string(), r.trace_sha256);
    out += '\n';
  }
  return out;
}

std::string strokes_csv(const StudyTables& tables, std::span<const MetricInfo> metrics) {
  const std::vector<MetricInfo> columns = study_metric_columns(StudyTable::strokes, metrics);
  std::string out =
      "subject,session,trial,phase,condition,character,character_text,stroke,typical_id,written,backwards,"
      "segments,refused_segments,refusal";
  out += metric_header(columns);
  out += '\n';
  for (const StrokeRow& r : tables.strokes) {
    out += field(r.subject);
    fields(out, r.session, r.trial, r.phase, r.condition, r.character, r.character_text, r.stroke,
           r.typical_id, r.written, r.backwards, r.segments, r.refused_segments, r.refusal);
    metric_fields(out, r.metrics, columns);
    out += '\n';
  }
  return out;
}

}  // namespace calligraphy
