#include "calligraphy/report/score_report.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "report/appendf.hpp"
#include "report/metrics_object.hpp"

namespace calligraphy {
namespace {

std::string fixed(const std::optional<double>& value, double scale, const char* pattern) {
  if (!value) return "-";
  char text[64];
  std::snprintf(text, sizeof text, pattern, *value * scale);
  return text;
}

// A summary's quantity with its unit, or "-" alone when there is none (as `trial`'s summary gives it): a
// person reads "-" as no value, never as one of "- mm".
std::string fixed(const std::optional<double>& value, double scale, const char* pattern, const char* unit) {
  return value ? fixed(value, scale, pattern) + " " + unit : "-";
}

nlohmann::json stroke_json(const StrokeScore& stroke) {
  nlohmann::json out = {{"index", stroke.index}, {"typical_id", stroke.typical_id}};
  report_detail::add_metrics(out, metric_level_stroke, stroke);
  return out;
}

constexpr StrokeRefusal kRefusals[] = {StrokeRefusal::too_short, StrokeRefusal::backwards,
                                       StrokeRefusal::wrong_place, StrokeRefusal::wrong_stroke,
                                       StrokeRefusal::wrong_order};

nlohmann::json refusals_json(const RefusalCounts& counts) {
  nlohmann::json out = nlohmann::json::object();
  for (const StrokeRefusal r : kRefusals) out[to_string(r)] = counts.of(r);
  return out;
}

// Every pen-down segment in writing order, with its match (for the metrics) and the renderer's verdict in
// sequence; sample indices (begin inclusive, end exclusive) and strokes 0-based.
nlohmann::json segments_json(const CharacterScore& score) {
  nlohmann::json out = nlohmann::json::array();
  for (const WrittenSegment& s : score.segments) {
    nlohmann::json verdict = nullptr;
    if (s.verdict) {
      const StrokeMatch& v = *s.verdict;
      verdict = {
          {"expected_stroke", s.due_stroke},
          {"accepted", v.accepted},
          {"refusal", to_string(v.refusal)},
          {"matched_stroke", v.matched_stroke},
          {"covered_fraction", v.covered_fraction},
          // No distance was measured from a stroke the pen never came near the start of.
          {"mean_deviation_m", v.entered ? nlohmann::json(v.mean_deviation_m) : nlohmann::json(nullptr)},
          // The stroke due was credited assisted after this refusal (assist_after_misses): the next is due.
          {"assists_due", s.assists_due}};
    }
    out.push_back({{"begin", s.begin},
                   {"end", s.end},
                   {"ignored", s.ignored},
                   {"matched_stroke", s.matched_stroke ? nlohmann::json(*s.matched_stroke) : nullptr},
                   {"backwards", s.backwards},
                   {"verdict", verdict}});
  }
  return out;
}

}  // namespace

namespace {

// One verdict per reference stroke, from the renderer's verdicts on the pen-downs in writing order: accepted
// when a pen-down was accepted as it; assisted when it was credited after assist_after_misses refusals while
// it was due (the renderer's credit, so that the strokes after it are judged as the renderer judged them);
// else refused, by the last refusal about it (a wrong order or a wrong
// stroke is about the stroke the pen wrote, and so is a refused pen-down that wrote a later stroke from its
// end, so that such a stroke is not called not written; any other refusal about the stroke that was due);
// else not written.
struct StrokeVerdict {
  enum class State { not_written, accepted, assisted, refused } state = State::not_written;
  StrokeRefusal refusal = StrokeRefusal::none;
  std::size_t due = 0;            // the stroke due when it was refused (0-based)
  bool entered = false;           // the refused pen-down came near the start of the stroke that was due
  double deviation_m = 0.0;       // its mean distance from that stroke, when it did
  double covered_fraction = 0.0;  // how far along the stroke that was due it went
  bool out_of_turn = false;       // the pen-down wrote this stroke from its end while another was due
};

std::vector<StrokeVerdict> stroke_verdicts(const CharacterScore& score) {
  std::vector<StrokeVerdict> verdicts(score.strokes.size());
  for (const WrittenSegment& segment : score.segments) {
    if (!segment.verdict) continue;
    const StrokeMatch& match = *segment.verdict;
    const std::size_t due = segment.due_stroke;  // score_trace's, which counts the credits once
    if (match.accepted) {
      if (due < verdicts.size())
        verdicts[due] = {StrokeVerdict::State::accepted, StrokeRefusal::none, due, true, 0.0, 1.0};
      continue;
    }
    if (segment.assists_due) {
      // Its last refusal, as for a refused stroke, and the credit: what was off stays said.
      if (due < verdicts.size()) {
        verdicts[due] = {StrokeVerdict::State::assisted, match.refusal,         due, match.entered,
                         match.mean_deviation_m,         match.covered_fraction};
      }
      continue;
    }
    const bool other_stroke =
        match.refusal == StrokeRefusal::wrong_order || match.refusal == StrokeRefusal::wrong_stroke;
    // A pen-down refused while one stroke was due that wrote a later one from its end (the assignment matched
    // it backwards: a later stroke written backwards is `wrong_place`) is about the stroke it wrote.
    const bool out_of_turn = !other_stroke && segment.backwards && segment.matched_stroke &&
                             *segment.matched_stroke != due && *segment.matched_stroke < verdicts.size() &&
                             verdicts[*segment.matched_stroke].state != StrokeVerdict::State::accepted;
    const std::size_t about = other_stroke  ? match.matched_stroke
                              : out_of_turn ? *segment.matched_stroke
                                            : due;
    if (about >= verdicts.size() || verdicts[about].state == StrokeVerdict::State::accepted ||
        verdicts[about].state == StrokeVerdict::State::assisted)
      continue;
    verdicts[about] = {StrokeVerdict::State::refused, match.refusal,          due,        match.entered,
                       match.mean_deviation_m,        match.covered_fraction, out_of_turn};
  }
  return verdicts;
}

// "too_short" -> "too short".
std::string reason_words(StrokeRefusal refusal) {
  std::string words = to_string(refusal);
  for (char& c : words)
    if (c == '_') c = ' ';
  return words;
}

std::string verdict_text(const StrokeVerdict& v, std::size_t stroke) {
  char text[160];
  switch (v.state) {
    case StrokeVerdict::State::accepted:
      return "accepted";
    case StrokeVerdict::State::not_written:
      return "not written";
    case StrokeVerdict::State::assisted:
      // Credited, not written: the last refusal says what was off.
      if (!v.entered) return "assisted (last refused: " + reason_words(v.refusal) + ", never near its start)";
      std::snprintf(text, sizeof text, "assisted (last refused: %s, %.1f mm off)",
                    reason_words(v.refusal).c_str(), v.deviation_m * 1e3);
      return text;
    case StrokeVerdict::State::refused:
      break;
  }
  const std::string why = "refused: " + reason_words(v.refusal);
  if (v.out_of_turn) {
    std::snprintf(text, sizeof text, " (written backwards while stroke %zu was due)", v.due + 1);
    return why + text;
  }
  switch (v.refusal) {
    case StrokeRefusal::wrong_order:
      std::snprintf(text, sizeof text, " (written while stroke %zu was due)", v.due + 1);
      return why + text;
    case StrokeRefusal::wrong_stroke:
      if (v.due == stroke) return why;
      std::snprintf(text, sizeof text, " (written again while stroke %zu was due)", v.due + 1);
      return why + text;
    case StrokeRefusal::too_short:
      std::snprintf(text, sizeof text, " (%.0f %% of it, %.1f mm off)", v.covered_fraction * 100.0,
                    v.deviation_m * 1e3);
      return why + text;
    default:
      if (!v.entered) return why + " (never near its start)";
      std::snprintf(text, sizeof text, " (%.1f mm off)", v.deviation_m * 1e3);
      return why + text;
  }
}

// The verdicts' counts: accepted, assisted, refused (by reason), not written; they add up to the strokes.
struct VerdictCounts {
  std::size_t strokes = 0;
  std::size_t accepted = 0;
  std::size_t not_written = 0;
  std::size_t assisted = 0;
  RefusalCounts refused;
  void add(const std::vector<StrokeVerdict>& verdicts) {
    for (const StrokeVerdict& v : verdicts) {
      ++strokes;
      if (v.state == StrokeVerdict::State::accepted) ++accepted;
      if (v.state == StrokeVerdict::State::not_written) ++not_written;
      if (v.state == StrokeVerdict::State::assisted) ++assisted;
      if (v.state == StrokeVerdict::State::refused) refused.add(v.refusal);
    }
  }
};

std::string by_reason(const RefusalCounts& counts) {
  std::string text;
  for (const StrokeRefusal r : kRefusals) {
    if (counts.of(r) > 0)
      appendf(text, "%s%s %zu", text.empty() ? "" : ", ", reason_words(r).c_str(), counts.of(r));
  }
  return text.empty() ? "" : "  (" + text + ")";
}

void append_verdict_counts(std::string& out, const VerdictCounts& c) {
  appendf(out, "  strokes accepted           %zu of %zu  (in turn, as the renderer judges each pen lift)\n",
          c.accepted, c.strokes);
  if (c.assisted > 0) {
    appendf(
        out,
        "  strokes assisted           %zu  (credited after the refusals the renderer allows, not written)\n",
        c.assisted);
  }
  appendf(out, "  strokes refused            %zu%s\n", c.refused.total(), by_reason(c.refused).c_str());
  appendf(out, "  strokes not written        %zu\n", c.not_written);
}

void append_character_table(std::string& out, const CharacterScore& score) {
  const CharacterWritingMetrics& t = score.totals;
  const std::vector<StrokeVerdict> verdicts = stroke_verdicts(score);
  appendf(out, "\n  %-6s %-6s %-4s %9s %9s %11s %9s %9s  %s\n", "stroke", "type", "ID", "mean[mm]", "max[mm]",
          "Frechet[mm]", "DTW[mm]", "time[s]", "verdict");
  for (const StrokeScore& s : score.strokes) {
    const auto& m = s.metrics;
    const auto mm = [&](auto member) { return m ? std::optional<double>(member(*m)) : std::nullopt; };
    std::string verdict = verdict_text(verdicts[s.index], s.index);
    if (s.backwards && verdicts[s.index].refusal != StrokeRefusal::backwards &&
        !verdicts[s.index].out_of_turn)
      verdict += "; matched backwards";
    appendf(out, "  %-6zu %-6s %-4d %9s %9s %11s %9s %9s  %s\n", s.index + 1,
            std::string(typical_stroke(s.typical_id).acronym).c_str(), s.typical_id,
            fixed(mm([](auto& x) { return x.deviation.mean_m; }), 1e3, "%.2f").c_str(),
            fixed(mm([](auto& x) { return x.deviation.max_m; }), 1e3, "%.2f").c_str(),
            fixed(mm([](auto& x) { return x.curves.frechet_m; }), 1e3, "%.2f").c_str(),
            fixed(mm([](auto& x) { return x.curves.dtw_m; }), 1e3, "%.2f").c_str(),
            fixed(mm([](auto& x) { return x.kinematics.writing_time_s; }), 1.0, "%.2f").c_str(),
            verdict.c_str());
  }
  const auto deviation = [&](double DeviationSummary::*member) {
    return t.deviation ? std::optional<double>((*t.deviation).*member) : std::nullopt;
  };
  VerdictCounts counts;
  counts.add(verdicts);
  out += "\n";
  append_verdict_counts(out, counts);
  appendf(out, "  pen-downs refused          %zu%s\n", score.refusals.total(),
          by_reason(score.refusals).c_str());
  appendf(out, "  pen-downs unmatched        %zu, too short to score %zu\n", score.unmatched_strokes,
          score.ignored_segments);
  appendf(out, "  strokes matched            %zu  (the deviations and times below are theirs)\n",
          score.strokes_written);
  appendf(out, "  mean deviation             %s\n",
          fixed(deviation(&DeviationSummary::mean_m), 1e3, "%.3f", "mm").c_str());
  appendf(out, "  max deviation              %s\n",
          fixed(deviation(&DeviationSummary::max_m), 1e3, "%.3f", "mm").c_str());
  appendf(out, "  RMS deviation              %s\n",
          fixed(deviation(&DeviationSummary::rms_m), 1e3, "%.3f", "mm").c_str());
  appendf(out, "  Frechet (worst stroke)     %s\n", fixed(t.frechet_m, 1e3, "%.3f", "mm").c_str());
  appendf(out, "  DTW (mean)                 %s\n", fixed(t.dtw_m, 1e3, "%.3f", "mm").c_str());
  appendf(out, "  pen lifts                  %zu\n", t.pen_lifts);
  appendf(out, "  time                       %s (pen down %.2f s, in the air %.2f s)\n",
          fixed(t.total_time_s, 1.0, "%.2f", "s").c_str(), t.writing_time_s, t.in_air_time_s);
  appendf(out, "  mean speed                 %s\n", fixed(t.mean_speed_m_per_s, 1.0, "%.4f", "m/s").c_str());
  appendf(out, "  velocity peaks             %d\n", t.velocity_peaks);
  appendf(out, "  normalised jerk            %s\n", fixed(t.normalised_jerk, 1.0, "%.1f").c_str());
}

}  // namespace

std::string score_table(const ScoreDescription& d, const WritingMetrics& metrics) {
  std::string out;
  appendf(out,
          "Score of %s against %s (%zu samples, x and y in %s; strokes numbered from 1 here, from 0 in the "
          "JSON)\n",
          // The file's name as printable text: an escape sequence in it cannot act on the terminal.
          printable_one_line(d.trace).c_str(), d.character.c_str(), d.samples,
          // `--units data`: the character's 1024-unit data box, named as a unit for a person.
          d.units == "data" ? "data units (1024 per character)" : d.units.c_str());
  VerdictCounts all;
  for (const CharacterScore& score : metrics.characters) {
    if (metrics.characters.size() > 1) appendf(out, "\n%s\n", encode_utf8(score.code_point).c_str());
    append_character_table(out, score);
    all.add(stroke_verdicts(score));
  }
  if (metrics.characters.size() > 1) {
    const auto mm = [](const std::optional<double>& v) { return fixed(v, 1e3, "%.3f", "mm"); };
    appendf(out, "\nAll %zu characters\n", metrics.characters.size());
    append_verdict_counts(out, all);
    appendf(out, "  pen-downs refused          %zu%s\n", metrics.refusals.total(),
            by_reason(metrics.refusals).c_str());
    appendf(out, "  strokes matched            %zu  (the deviations and times below are theirs)\n",
            metrics.strokes_written);
    appendf(out, "  mean deviation             %s\n",
            mm(metrics.deviation ? std::optional<double>(metrics.deviation->mean_m) : std::nullopt).c_str());
    appendf(out, "  Frechet (worst stroke)     %s\n", mm(metrics.frechet_m).c_str());
    appendf(out, "  DTW (mean)                 %s\n", mm(metrics.dtw_m).c_str());
    appendf(out, "  time                       %s (pen down %.2f s)\n",
            fixed(metrics.total_time_s, 1.0, "%.2f", "s").c_str(), metrics.pen_down_time_s);
  }
  return out;
}

namespace {

// One character's score: every key of docs/metrics.md's per-character record.
nlohmann::json character_object(const CharacterScore& score) {
  nlohmann::json per_stroke = nlohmann::json::array();
  for (const StrokeScore& s : score.strokes) per_stroke.push_back(stroke_json(s));
  nlohmann::json out = {{"character", encode_utf8(score.code_point)},
                        {"refusals", refusals_json(score.refusals)},
                        {"missing_strokes", score.missing_strokes},
                        {"per_stroke", per_stroke},
                        {"segments", segments_json(score)}};
  report_detail::add_metrics(out, metric_level_character, score);
  return out;
}

}  // namespace

nlohmann::json report_detail::writing_metrics_object(const WritingMetrics& m) {
  nlohmann::json characters = nlohmann::json::array();
  for (const CharacterScore& score : m.characters) characters.push_back(character_object(score));
  nlohmann::json out = {{"refusals", refusals_json(m.refusals)}, {"per_character", characters}};
  report_detail::add_metrics(out, metric_level_scene, m);
  return out;
}

std::string writing_metrics_json(const WritingMetrics& metrics) {
  return json_text(report_detail::writing_metrics_object(metrics), 2) + "\n";
}

std::string score_json(const ScoreDescription& d, const WritingMetrics& metrics) {
  nlohmann::json doc = {
      {"character", d.character}, {"trace", d.trace}, {"units", d.units}, {"samples", d.samples}};
  doc.update(report_detail::writing_metrics_object(metrics));
  return json_text(doc, 2) + "\n";
}

}  // namespace calligraphy
