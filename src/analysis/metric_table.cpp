#include "calligraphy/analysis/metric_table.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <tuple>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

constexpr std::uint8_t kScene = metric_level_scene;
constexpr std::uint8_t kCharacter = metric_level_character;
constexpr std::uint8_t kStroke = metric_level_stroke;
constexpr std::uint8_t kRun = metric_level_run;

MetricValue number(const std::optional<double>& value) {
  return value ? MetricValue(*value) : MetricValue(std::monostate{});
}
MetricValue count(std::size_t value) { return MetricValue(static_cast<std::int64_t>(value)); }
MetricValue count(int value) { return MetricValue(static_cast<std::int64_t>(value)); }

// One member of a deviation summary; null without a summary (nothing matched).
MetricValue deviation(const std::optional<DeviationSummary>& summary, double DeviationSummary::*member) {
  return summary ? MetricValue((*summary).*member) : MetricValue(std::monostate{});
}

// A stroke's metrics, null for a stroke never written.
template <typename F>
MetricValue of_written(const StrokeScore& stroke, F value) {
  return stroke.metrics ? value(*stroke.metrics) : MetricValue(std::monostate{});
}

constexpr std::string_view kFrechetSource = "Eiter & Mannila 1994";
constexpr std::string_view kDtwSource = "Sakoe & Chiba 1978";
constexpr std::string_view kJerkSource = "Teulings et al. 1997; Hogan & Sternad 2009";
constexpr std::string_view kLowPassSource = "Teulings & Maarse 1984";

const MetricInfo kMetrics[] = {
    // ---- counts and flags of the matching
    {.name = "strokes_total",
     .kind = MetricKind::count,
     .doc = "reference strokes",
     .definition = "strokes of the scene's (or the character's) reference",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.strokes_total); },
     .of_character = [](const CharacterScore& c) { return count(c.strokes.size()); },
     .trials_column = 2,
     .if_missing = MetricMissing::refused},
    {.name = "strokes_written",
     .kind = MetricKind::count,
     .doc = "reference strokes matched to a written segment",
     .definition = "strokes the one-to-one assignment gave a segment (`score_trace`)",
     .source = "Kuhn 1955; Munkres 1957",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.strokes_written); },
     .of_character = [](const CharacterScore& c) { return count(c.strokes_written); },
     .trials_column = 3,
     .if_missing = MetricMissing::refused},
    {.name = "strokes_accepted",
     .kind = MetricKind::count,
     .doc = "segments accepted in turn, as the renderer and the quiz judge them",
     .definition = "accepted verdicts of `match_stroke` in writing order",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.strokes_accepted); },
     .of_character = [](const CharacterScore& c) { return count(c.strokes_accepted); },
     .trials_column = 4,
     .if_missing = MetricMissing::refused},
    {.name = "completed_in_order",
     .kind = MetricKind::flag,
     .doc = "every stroke written and no order error",
     .definition = "strokes_written = strokes_total and order_errors = 0 (every character)",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return MetricValue(m.completed_in_order); },
     .of_character = [](const CharacterScore& c) { return MetricValue(c.completed_in_order); },
     .trials_column = 1,
     .if_missing = MetricMissing::zero},
    {.name = "strokes_in_order",
     .kind = MetricKind::flag,
     .doc = "at least one stroke written and no order error",
     .definition = "strokes_written > 0 and order_errors = 0",
     .levels = kCharacter,
     .of_character = [](const CharacterScore& c) { return MetricValue(c.strokes_in_order); }},
    {.name = "order_errors",
     .kind = MetricKind::count,
     .doc = "pairs of matched segments written in the reverse of their reference order",
     .definition = "inversions of the matched stroke indices in writing order, summed over characters",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.order_errors); },
     .of_character = [](const CharacterScore& c) { return count(c.order_errors); },
     .trials_column = 6,
     .if_missing = MetricMissing::refused},
    {.name = "backwards_strokes",
     .kind = MetricKind::count,
     .doc = "matched segments written from the stroke's end",
     .definition = "pairs the matcher accepted with the segment's points reversed",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.backwards_strokes); },
     .of_character = [](const CharacterScore& c) { return count(c.backwards_strokes); },
     .trials_column = 7,
     .if_missing = MetricMissing::refused},
    {.name = "unmatched_segments",
     .kind = MetricKind::count,
     .doc = "scored segments matched to no reference stroke",
     .definition = "scored segments the assignment left without a stroke",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return count(m.unmatched_segments); },
     .of_character = [](const CharacterScore& c) { return count(c.unmatched_strokes); },
     .trials_column = 8,
     .if_missing = MetricMissing::refused},
    {.name = "ignored_segments",
     .kind = MetricKind::count,
     .doc = "pen-down segments too short to score",
     .definition = "fewer than 3 samples, a path under 1 mm or no time span",
     .levels = kCharacter,
     .of_character = [](const CharacterScore& c) { return count(c.ignored_segments); }},
    {.name = "pen_lifts",
     .kind = MetricKind::count,
     .doc = "pen-up gaps between two pen-down segments",
     .definition = "pen-down segments - 1 (ignored ones included)",
     .levels = kCharacter,
     .of_character = [](const CharacterScore& c) { return count(c.totals.pen_lifts); }},
    {.name = "written",
     .kind = MetricKind::flag,
     .doc = "a written segment was matched to the stroke",
     .definition = "the assignment gave the stroke a segment",
     .levels = kStroke,
     .of_stroke = [](const StrokeScore& s) { return MetricValue(s.written); }},
    {.name = "assisted",
     .kind = MetricKind::flag,
     .doc = "credited assisted in turn after `assist_after_misses` refused attempts while it was due",
     .definition = "`StrokeScore::assisted` (`score_trace`, as the renderer credits it)",
     .levels = kStroke,
     .of_stroke = [](const StrokeScore& s) { return MetricValue(s.assisted); },
     .strokes_column = 8,
     .if_missing = MetricMissing::zero},
    {.name = "backwards",
     .kind = MetricKind::flag,
     .doc = "the stroke was written from its end to its start",
     .definition = "matched with the segment's points reversed",
     .levels = kStroke,
     .of_stroke = [](const StrokeScore& s) { return MetricValue(s.backwards); }},
    // ---- spatial
    {.name = "mean_deviation_m",
     .unit = "m",
     .doc = "mean distance of the written samples from the reference stroke",
     .definition = "sum(d_i) / N, d_i the exact nearest point's distance; pooled over matched strokes",
     .levels = kScene | kCharacter | kStroke,
     .legacy_name = "mean_deviation_mm",
     .legacy_factor = 1e3,
     .of_scene = [](const WritingMetrics& m) { return deviation(m.deviation, &DeviationSummary::mean_m); },
     .of_character =
         [](const CharacterScore& c) { return deviation(c.totals.deviation, &DeviationSummary::mean_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(s,
                             [](const StrokeWritingMetrics& w) { return MetricValue(w.deviation.mean_m); });
         },
     .trials_column = 9,
     .strokes_column = 1},
    {.name = "max_deviation_m",
     .unit = "m",
     .doc = "largest distance of a written sample from the reference stroke",
     .definition = "max(d_i); max of the strokes' maxima",
     .levels = kScene | kCharacter | kStroke,
     .legacy_name = "max_deviation_mm",
     .legacy_factor = 1e3,
     .of_scene = [](const WritingMetrics& m) { return deviation(m.deviation, &DeviationSummary::max_m); },
     .of_character =
         [](const CharacterScore& c) { return deviation(c.totals.deviation, &DeviationSummary::max_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(s, [](const StrokeWritingMetrics& w) { return MetricValue(w.deviation.max_m); });
         },
     .trials_column = 10,
     .strokes_column = 2},
    {.name = "rms_deviation_m",
     .unit = "m",
     .doc = "root mean square distance of the written samples from the reference stroke",
     .definition = "sqrt(sum(d_i^2) / N); from the pooled mean square",
     .levels = kScene | kCharacter | kStroke,
     .legacy_name = "rms_deviation_mm",
     .legacy_factor = 1e3,
     .of_scene = [](const WritingMetrics& m) { return deviation(m.deviation, &DeviationSummary::rms_m); },
     .of_character =
         [](const CharacterScore& c) { return deviation(c.totals.deviation, &DeviationSummary::rms_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(s, [](const StrokeWritingMetrics& w) { return MetricValue(w.deviation.rms_m); });
         },
     .trials_column = 11,
     .strokes_column = 3},
    {.name = "outside_tube_share",
     .doc = "share of the samples farther than the tube radius (2 mm) from the stroke",
     .definition = "#{i : d_i > r} / N",
     .levels = kStroke,
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return MetricValue(w.deviation.outside_tube_share); });
         }},
    {.name = "frechet_m",
     .unit = "m",
     .doc = "discrete Frechet distance between the written and the resampled reference stroke",
     .definition = "`compare_curves`; max over matched strokes",
     .source = kFrechetSource,
     .levels = kScene | kCharacter | kStroke,
     .legacy_name = "frechet_mm",
     .legacy_factor = 1e3,
     .of_scene = [](const WritingMetrics& m) { return number(m.frechet_m); },
     .of_character = [](const CharacterScore& c) { return number(c.totals.frechet_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(s,
                             [](const StrokeWritingMetrics& w) { return MetricValue(w.curves.frechet_m); });
         },
     .trials_column = 12,
     .strokes_column = 4},
    {.name = "dtw_m",
     .unit = "m",
     .doc = "mean point distance along the optimal dynamic time warping path",
     .definition = "`compare_curves`: D(n-1, m-1) / K; mean over matched strokes weighted by samples",
     .source = kDtwSource,
     .levels = kScene | kCharacter | kStroke,
     .legacy_name = "dtw_mm",
     .legacy_factor = 1e3,
     .of_scene = [](const WritingMetrics& m) { return number(m.dtw_m); },
     .of_character = [](const CharacterScore& c) { return number(c.totals.dtw_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(s, [](const StrokeWritingMetrics& w) { return MetricValue(w.curves.dtw_m); });
         },
     .trials_column = 13,
     .strokes_column = 5},
    {.name = "path_length_m",
     .unit = "m",
     .doc = "pen-down path length",
     .definition = "sum |p_(i+1) - p_i| over the raw samples; over all segments",
     .levels = kCharacter | kStroke,
     .legacy_name = "path_length_mm",
     .legacy_factor = 1e3,
     .of_character = [](const CharacterScore& c) { return MetricValue(c.totals.path_length_m); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return MetricValue(w.kinematics.path_length_m); });
         },
     .strokes_column = 7},
    // ---- times and fluency
    {.name = "total_time_s",
     .unit = "s",
     .doc = "first pen-down sample to last pen-down sample; null when the pen never touched",
     .definition = "writing time + in-air time, rounded to whole nanoseconds",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return number(m.total_time_s); },
     .of_character = [](const CharacterScore& c) { return number(c.totals.total_time_s); },
     .trials_column = 14,
     .if_missing = MetricMissing::refused},
    {.name = "pen_down_time_s",
     .unit = "s",
     .doc = "time with the pen down",
     .definition = "sum over pen-down segments of t_last - t_first",
     .levels = kScene | kCharacter,
     .of_scene = [](const WritingMetrics& m) { return MetricValue(m.pen_down_time_s); },
     .of_character = [](const CharacterScore& c) { return MetricValue(c.totals.writing_time_s); },
     .trials_column = 15,
     .if_missing = MetricMissing::refused},
    {.name = "in_air_time_s",
     .unit = "s",
     .doc = "time with the pen lifted between two pen-down segments",
     .definition = "sum over gaps of t_first(next segment) - t_last(segment)",
     .levels = kCharacter,
     .of_character = [](const CharacterScore& c) { return MetricValue(c.totals.in_air_time_s); }},
    {.name = "time_s",
     .unit = "s",
     .doc = "writing time of the segment matched to the stroke",
     .definition = "t_(N-1) - t_0, rounded to whole nanoseconds",
     .levels = kStroke,
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return MetricValue(w.kinematics.writing_time_s); });
         },
     .strokes_column = 6},
    {.name = "mean_speed_m_s",
     .unit = "m/s",
     .doc = "mean pen-down speed",
     .definition = "path length / writing time",
     .levels = kCharacter | kStroke,
     .of_character = [](const CharacterScore& c) { return number(c.totals.mean_speed_m_per_s); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return MetricValue(w.kinematics.mean_speed_m_per_s); });
         }},
    {.name = "velocity_peaks",
     .kind = MetricKind::count,
     .doc = "peaks of the low-passed speed (fewer: a more fluent stroke)",
     .definition = "10 % prominence with hysteresis on the 10 Hz low-passed speed; summed over segments",
     .source = kLowPassSource,
     .levels = kScene | kCharacter | kStroke,
     .of_scene = [](const WritingMetrics& m) { return count(m.velocity_peaks); },
     .of_character = [](const CharacterScore& c) { return count(c.totals.velocity_peaks); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return count(w.kinematics.velocity_peaks); });
         },
     .trials_column = 16,
     .if_missing = MetricMissing::refused},
    {.name = "normalised_jerk",
     .doc = "dimensionless jerk of the low-passed pen path (sqrt(360) for a minimum-jerk movement)",
     .definition = "sqrt(0.5 integral |x'''|^2 dt T^5 / L^2); mean over scored segments",
     .source = kJerkSource,
     .levels = kScene | kCharacter | kStroke,
     .of_scene = [](const WritingMetrics& m) { return number(m.normalised_jerk); },
     .of_character = [](const CharacterScore& c) { return number(c.totals.normalised_jerk); },
     .of_stroke =
         [](const StrokeScore& s) {
           return of_written(
               s, [](const StrokeWritingMetrics& w) { return MetricValue(w.kinematics.normalised_jerk); });
         },
     .trials_column = 17},
    // ---- the live run, as the renderer saw it (TrialMetrics, trial/recorder.hpp)
    {.name = "strokes_completed",
     .kind = MetricKind::count,
     .doc = "strokes the renderer completed in turn, written by the pen",
     .definition = "`TrialMetrics::strokes_completed`",
     .levels = kRun},
    {.name = "strokes_assisted",
     .kind = MetricKind::count,
     .doc = "strokes credited as assisted after `assist_after_misses` refused attempts (not taken by the "
            "renderer)",
     .definition =
         "a run's: `TrialMetrics::strokes_assisted`; a scored trace's: strokes credited in turn after "
         "`assist_after_misses` refused verdicts of pen-downs that count as the renderer's misses "
         "(`StrokeAcceptance::counts_as_miss`, `score_trace`)",
     .levels = kScene | kCharacter | kRun,
     .of_scene = [](const WritingMetrics& m) { return count(m.strokes_assisted); },
     .of_character = [](const CharacterScore& c) { return count(c.strokes_assisted); },
     .trials_column = 5,
     .if_missing = MetricMissing::zero},
    {.name = "trial_time_s",
     .unit = "s",
     .doc = "from the trial's start to the last stroke completed (or the end of the trial)",
     .definition = "`TrialMetrics::time_s`",
     .levels = kRun},
    {.name = "max_force_n",
     .unit = "N",
     .doc = "largest force commanded",
     .definition = "max |F| over the ticks",
     .levels = kRun},
    {.name = "max_force_step_n",
     .unit = "N",
     .doc = "largest change of the commanded force between two ticks",
     .definition = "max |F(k) - F(k-1)| over the ticks",
     .levels = kRun},
    {.name = "state_transitions",
     .kind = MetricKind::count,
     .doc = "changes of the interaction state (SS, AS, CS, WS)",
     .definition = "`TrialMetrics::state_transitions`",
     .source = "Wang, Zhang & Yao 2006",
     .levels = kRun},
    {.name = "readings_rejected",
     .kind = MetricKind::count,
     .doc =
         "ticks whose device reading was no pen (not finite, or beyond 10 m): zero force, the last accepted "
         "position kept in the trace",
     .definition = "`TrialMetrics::readings_rejected`: ticks with `RenderOutput::input_rejected`",
     .levels = kRun,
     .if_missing = MetricMissing::zero},
};

std::string_view kind_text(MetricKind kind) {
  switch (kind) {
    case MetricKind::count:
      return "count";
    case MetricKind::flag:
      return "flag";
    case MetricKind::number:
      break;
  }
  return "number";
}

// "|" would end a Markdown table cell.
std::string cell(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

std::span<const MetricInfo> metric_table() noexcept { return kMetrics; }

std::vector<MetricInfo> study_metric_columns(StudyTable which, std::span<const MetricInfo> table) {
  std::vector<MetricInfo> out;
  for (const MetricInfo& info : table)
    if (info.column(which) > 0) out.push_back(info);
  std::stable_sort(out.begin(), out.end(), [which](const MetricInfo& a, const MetricInfo& b) {
    return a.column(which) < b.column(which);
  });
  return out;
}

namespace {

// The metric columns of study table `which` in `table`: their names and their values before any is set (a
// number null, a count 0, a flag false).
std::pair<std::vector<std::string_view>, std::vector<MetricValue>> empty_columns(
    StudyTable which, std::span<const MetricInfo> table) {
  std::pair<std::vector<std::string_view>, std::vector<MetricValue>> columns;
  for (const MetricInfo& info : study_metric_columns(which, table)) {
    columns.first.push_back(info.name);
    switch (info.kind) {
      case MetricKind::count:
        columns.second.emplace_back(std::int64_t{0});
        break;
      case MetricKind::flag:
        columns.second.emplace_back(false);
        break;
      case MetricKind::number:
        columns.second.emplace_back(std::monostate{});
        break;
    }
  }
  return columns;
}

}  // namespace

MetricValues::MetricValues(StudyTable which, std::span<const MetricInfo> table) {
  // Every row of a study's tables starts from the library table's columns: found and sorted once, then
  // copied.
  if (table.data() == metric_table().data() && table.size() == metric_table().size()) {
    static const auto trials = empty_columns(StudyTable::trials, metric_table());
    static const auto strokes = empty_columns(StudyTable::strokes, metric_table());
    const auto& columns = which == StudyTable::trials ? trials : strokes;
    names_ = columns.first;
    values_ = columns.second;
    return;
  }
  std::tie(names_, values_) = empty_columns(which, table);
}

std::size_t MetricValues::index(std::string_view name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return i;
  std::string message = "the row has no metric column '";
  message.append(name);
  message += "'";
  throw InvalidArgument(message);
}

const MetricValue& MetricValues::at(std::string_view name) const { return values_[index(name)]; }

std::optional<double> MetricValues::number(std::string_view name) const {
  const MetricValue& value = at(name);
  if (const double* x = std::get_if<double>(&value)) return *x;
  if (const std::int64_t* n = std::get_if<std::int64_t>(&value)) return static_cast<double>(*n);
  if (const bool* flag = std::get_if<bool>(&value)) return *flag ? 1.0 : 0.0;
  return std::nullopt;
}

void MetricValues::set(std::string_view name, MetricValue value) { values_[index(name)] = std::move(value); }

std::optional<MetricInfo> find_metric(std::string_view text, std::span<const MetricInfo> table) noexcept {
  for (const MetricInfo& info : table) {
    if (info.name == text || (!info.legacy_name.empty() && info.legacy_name == text)) return info;
  }
  return std::nullopt;
}

const MetricInfo& metric(std::string_view name) {
  for (const MetricInfo& info : kMetrics) {
    if (info.name == name) return info;
  }
  std::string message = "the metric table has no metric '";
  message.append(name);
  message += "'";
  throw InvalidArgument(message);
}

std::string metric_levels_text(std::uint8_t levels) {
  std::string out;
  const auto add = [&](std::uint8_t bit, const char* text) {
    if ((levels & bit) == 0) return;
    if (!out.empty()) out += ", ";
    out += text;
  };
  add(kScene, "scene");
  add(kCharacter, "character");
  add(kStroke, "stroke");
  add(kRun, "run");
  return out;
}

std::string metric_markdown(std::span<const MetricInfo> table) {
  std::string out =
      "| metric | kind | unit | levels | what it is | how it is computed | before |\n"
      "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const MetricInfo& info : table) {
    out += "| `";
    out.append(info.name);
    out += "` | ";
    out.append(kind_text(info.kind));
    out += " | ";
    if (!info.unit.empty())
      out += cell(info.unit);
    else
      out += info.kind == MetricKind::number ? "1" : "-";
    out += " | ";
    out += metric_levels_text(info.levels);
    out += " | ";
    out += cell(info.doc);
    out += " | ";
    out += cell(info.definition);
    if (!info.source.empty()) {
      out += " (";
      out += cell(info.source);
      out += ")";
    }
    out += " | ";
    if (!info.legacy_name.empty()) {
      out += "`";
      out.append(info.legacy_name);
      out += "`";
    }
    out += " |\n";
  }
  return out;
}

std::string metric_json_schema(MetricLevel level, std::span<const MetricInfo> table) {
  nlohmann::ordered_json properties = nlohmann::ordered_json::object();
  for (const MetricInfo& info : table) {
    if (!info.at(level)) continue;
    std::string description(info.doc);
    if (!info.unit.empty()) {
      description += " [";
      description.append(info.unit);
      description += "]";
    }
    nlohmann::ordered_json property = nlohmann::ordered_json::object();
    switch (info.kind) {
      case MetricKind::number:
        property["type"] = nlohmann::ordered_json::array({"number", "null"});
        break;
      case MetricKind::count:  // a stroke never written has none
        if (level == metric_level_stroke)
          property["type"] = nlohmann::ordered_json::array({"integer", "null"});
        else
          property["type"] = "integer";
        property["minimum"] = 0;
        break;
      case MetricKind::flag:
        property["type"] = "boolean";
        break;
    }
    property["description"] = description;
    properties[std::string(info.name)] = property;
  }
  nlohmann::ordered_json schema = nlohmann::ordered_json::object();
  schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  std::string id = "https://calligraphy.invalid/schema/metrics-";
  id += metric_levels_text(level);
  id += ".json";
  schema["$id"] = id;
  std::string title = "calligraphy metrics of a record, ";
  title += metric_levels_text(level);
  title += " level";
  schema["title"] = title;
  schema["type"] = "object";
  schema["properties"] = properties;
  std::vector<std::string> required;
  for (const auto& item : properties.items()) required.push_back(item.key());
  schema["required"] = required;
  return schema.dump(2) + "\n";
}

}  // namespace calligraphy
