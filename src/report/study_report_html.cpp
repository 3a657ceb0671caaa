// The study report page (study_report_html.hpp): tables, learning curves and per-trial figures as
// inline SVG.
#include "calligraphy/report/study_report_html.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "report/appendf.hpp"

namespace calligraphy {
namespace {

constexpr std::array<const char*, 6> kConditionColours{"#d62728", "#1f77b4", "#2ca02c",
                                                       "#9467bd", "#ff7f0e", "#8c564b"};

std::string escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string number(double value, int decimals) {
  if (!std::isfinite(value)) return "&ndash;";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

const char* colour_of(const StudyReport& report, const std::string& condition) {
  const auto found = std::find(report.conditions.begin(), report.conditions.end(), condition);
  const auto index = static_cast<std::size_t>(found - report.conditions.begin());
  return kConditionColours[index % kConditionColours.size()];
}

std::optional<double> recorded_value(const ReportTrial& trial, ReportMeasure measure) {
  switch (measure) {
    case ReportMeasure::time_s:
      return trial.time_total_s;
    case ReportMeasure::mean_deviation_mm:
      return trial.mean_deviation_mm;
    case ReportMeasure::frechet_mm:
      return trial.frechet_mm;
    case ReportMeasure::order_errors:
      return static_cast<double>(trial.order_errors);
  }
  return std::nullopt;
}

// A trial's value of a measure; none for one it lacks or that is not finite (a trial that wrote no stroke
// has no deviation), so that a summary counts and averages only the values there are.
std::optional<double> value_of(const ReportTrial& trial, ReportMeasure measure) {
  const std::optional<double> value = recorded_value(trial, measure);
  return value && std::isfinite(*value) ? value : std::nullopt;
}

struct MeasureInfo {
  ReportMeasure measure;
  const char* title;
  const char* unit;
  int decimals;
};
constexpr std::array<MeasureInfo, 4> kMeasures{{
    {ReportMeasure::time_s, "Writing time", "s", 1},
    {ReportMeasure::mean_deviation_mm, "Mean deviation", "mm", 2},
    {ReportMeasure::frechet_mm, "Fr&eacute;chet distance (worst stroke)", "mm", 2},
    {ReportMeasure::order_errors, "Stroke order errors", "pairs", 2},
}};

// ---- Summary tables ----------------------------------------------------------------------------

std::string cell(const MeanSd& summary, int decimals) {
  if (summary.n == 0) return "<td class=\"num\">&ndash;</td>";
  std::string out = "<td class=\"num\">" + number(summary.mean, decimals);
  if (summary.n >= 2) out += " &plusmn; " + number(summary.sd, decimals);
  out += " <span class=\"n\">(" + std::to_string(summary.n) + ")</span></td>";
  return out;
}

void append_summary_table(std::string& out, const StudyReport& report, const MeasureInfo& info) {
  appendf(out,
          "<table class=\"summary\" data-measure=\"%s\">\n<caption>%s [%s]: mean &plusmn; SD (n) over "
          "subjects and repetitions</caption>\n<tr><th>Condition</th>",
          info.unit, info.title, info.unit);
  for (std::size_t i = 0; i < report.items.size(); ++i) {
    appendf(out, "<th>C%zu %s</th>", i + 1, escape(report.items[i]).c_str());
  }
  out += "<th>all</th></tr>\n";
  for (const std::string& condition : report.conditions) {
    appendf(out, "<tr><th style=\"color:%s\">%s</th>", colour_of(report, condition),
            escape(condition).c_str());
    for (std::size_t i = 0; i < report.items.size(); ++i) {
      out += cell(mean_and_sd(measure_values(report, info.measure, condition, i)), info.decimals);
    }
    out += cell(mean_and_sd(measure_values(report, info.measure, condition)), info.decimals);
    out += "</tr>\n";
  }
  out += "</table>\n";
}

// ---- Learning curves ---------------------------------------------------------------------------

void append_learning_curve(std::string& out, const StudyReport& report, const MeasureInfo& info) {
  int repetitions = 0;
  for (const ReportTrial& t : report.trials) {
    if (t.phase == report.phase) repetitions = std::max(repetitions, t.repetition);
  }
  if (repetitions == 0) return;
  struct Point {
    int repetition;
    MeanSd summary;
  };
  std::map<std::string, std::vector<Point>> curves;
  double high = 0.0;
  for (const std::string& condition : report.conditions) {
    for (int r = 1; r <= repetitions; ++r) {
      const MeanSd s = mean_and_sd(measure_values(report, info.measure, condition, std::nullopt, r));
      if (s.n == 0) continue;
      curves[condition].push_back({r, s});
      high = std::max(high, s.mean + (std::isfinite(s.sd) ? s.sd : 0.0));
    }
  }
  if (high <= 0.0) high = 1.0;
  constexpr double kWidth = 420.0, kHeight = 220.0, kLeft = 48.0, kRight = 80.0, kTop = 14.0, kBottom = 34.0;
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  const auto x_of = [&](double r) {
    return kLeft + (repetitions == 1 ? plot_w / 2 : (r - 1.0) / (repetitions - 1.0) * plot_w);
  };
  const auto y_of = [&](double v) { return kTop + plot_h * (1.0 - v / (high * 1.05)); };
  appendf(out,
          "<figure class=\"learning-curve\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" "
          "height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" role=\"img\">\n",
          kWidth, kHeight, kWidth, kHeight);
  appendf(out, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#999\"/>\n",
          kLeft, kTop, plot_w, plot_h);
  for (int k = 0; k <= 4; ++k) {  // y ticks
    const double v = high * 1.05 * k / 4.0;
    appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\">%s</text>\n", kLeft - 4,
            y_of(v) + 3, number(v, info.decimals > 1 ? 1 : 0).c_str());
  }
  for (int r = 1; r <= repetitions; ++r) {
    appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"middle\">%d</text>\n", x_of(r),
            kTop + plot_h + 13, r);
  }
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"middle\">repetition</text>\n",
          kLeft + plot_w / 2, kHeight - 4);
  double legend_y = kTop + 10;
  for (const auto& [condition, points] : curves) {
    const char* colour = colour_of(report, condition);
    out += "<polyline fill=\"none\" stroke-width=\"2\" stroke=\"" + std::string(colour) + "\" points=\"";
    for (const Point& p : points) appendf(out, "%.1f,%.1f ", x_of(p.repetition), y_of(p.summary.mean));
    out += "\"/>\n";
    for (const Point& p : points) {
      const double x = x_of(p.repetition) + (colour == kConditionColours[0] ? -3.0 : 3.0);
      if (std::isfinite(p.summary.sd)) {
        appendf(out, "<line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", x, x,
                y_of(std::max(0.0, p.summary.mean - p.summary.sd)), y_of(p.summary.mean + p.summary.sd),
                colour);
      }
      appendf(out, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", x_of(p.repetition),
              y_of(p.summary.mean), colour);
    }
    appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" fill=\"%s\">%s</text>\n", kLeft + plot_w + 8,
            legend_y, colour, escape(condition).c_str());
    legend_y += 14;
  }
  appendf(out,
          "</svg><figcaption>%s [%s] over repetitions, mean &plusmn; SD over subjects and "
          "characters</figcaption></figure>\n",
          info.title, info.unit);
}

// ---- Per-trial figures -------------------------------------------------------------------------

// Trajectory over the reference: reference strokes in blue, pen-down trace in green, start points as red
// ellipses (the paper's display, section 7.2).
void append_trajectory_figure(std::string& out, const ReportTrial& trial) {
  Eigen::AlignedBox2d box;
  for (const auto& stroke : trial.reference_m) {
    for (const Vec2& p : stroke) box.extend(p);
  }
  if (box.isEmpty()) {
    for (std::size_t i = 0; i < trial.position_m.size(); ++i) {
      if (trial.pen_down[i]) box.extend(trial.position_m[i]);
    }
  }
  if (box.isEmpty()) box.extend(Vec2::Zero());
  const double margin = 0.008;
  const Vec2 lo = box.min() - Vec2(margin, margin);
  const Vec2 size = box.sizes() + Vec2(2 * margin, 2 * margin);
  const double side_m = std::max(size.x(), size.y());
  const double width_px = std::clamp(220.0 * size.x() / side_m, 120.0, 440.0);
  const double scale = width_px / size.x();  // px per metre
  const double height_px = size.y() * scale;
  const auto px = [&](const Vec2& p) {
    return Vec2((p.x() - lo.x()) * scale, (lo.y() + size.y() - p.y()) * scale);
  };
  appendf(out,
          "<figure class=\"trajectory\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" "
          "height=\"%.0f\" viewBox=\"0 0 %.1f %.1f\" role=\"img\"><rect width=\"100%%\" height=\"100%%\" "
          "fill=\"#fff\"/>\n",
          width_px, height_px, width_px, height_px);
  for (const auto& stroke : trial.reference_m) {
    out +=
        "<polyline fill=\"none\" stroke=\"#3060d0\" stroke-opacity=\"0.6\" stroke-width=\"5\" "
        "stroke-linecap=\"round\" stroke-linejoin=\"round\" points=\"";
    for (const Vec2& p : stroke) appendf(out, "%.1f,%.1f ", px(p).x(), px(p).y());
    out += "\"/>\n";
  }
  // Pen-down runs, thinned to points at least 0.25 mm apart.
  const double min_step_m = 0.25e-3;
  bool open = false;
  Vec2 last = Vec2::Zero();
  for (std::size_t i = 0; i < trial.position_m.size(); ++i) {
    const Vec2& p = trial.position_m[i];
    if (!trial.pen_down[i]) {
      if (open) out += "\"/>\n";
      open = false;
      continue;
    }
    if (!open) {
      out +=
          "<polyline fill=\"none\" stroke=\"#20b020\" stroke-width=\"1.6\" stroke-linejoin=\"round\" "
          "points=\"";
      open = true;
    } else if ((p - last).norm() < min_step_m && i + 1 < trial.position_m.size() && trial.pen_down[i + 1]) {
      continue;
    }
    appendf(out, "%.1f,%.1f ", px(p).x(), px(p).y());
    last = p;
  }
  if (open) out += "\"/>\n";
  for (const Vec2& start : trial.stroke_starts_m) {
    appendf(out, "<ellipse cx=\"%.1f\" cy=\"%.1f\" rx=\"4\" ry=\"3\" fill=\"none\" stroke=\"#e02020\"/>\n",
            px(start).x(), px(start).y());
  }
  appendf(out,
          "</svg><figcaption>Trajectory: reference (blue), pen on paper (green), stroke starts "
          "(red)</figcaption></figure>\n");
}

// In-plane force |F_xy| over time, each stroke's span shaded and its start and end marked.
void append_force_figure(std::string& out, const ReportTrial& trial) {
  constexpr double kWidth = 380.0, kHeight = 170.0, kLeft = 38.0, kRight = 8.0, kTop = 8.0, kBottom = 28.0;
  const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  const double t0 = trial.time_s.empty() ? 0.0 : trial.time_s.front();
  const double t1 = trial.time_s.empty() ? 1.0 : std::max(trial.time_s.back(), t0 + 1e-3);
  double f_max = 0.0;
  for (const double f : trial.in_plane_force_n) f_max = std::max(f_max, f);
  f_max = f_max > 0.0 ? f_max * 1.1 : 1.0;
  const auto x_of = [&](double t) { return kLeft + (t - t0) / (t1 - t0) * plot_w; };
  const auto y_of = [&](double f) { return kTop + plot_h * (1.0 - f / f_max); };
  appendf(out,
          "<figure class=\"force\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
          "viewBox=\"0 0 %.0f %.0f\" role=\"img\"><rect width=\"100%%\" height=\"100%%\" fill=\"#fff\"/>\n",
          kWidth, kHeight, kWidth, kHeight);
  for (const ReportStrokeSpan& s : trial.strokes) {
    appendf(
        out,
        "<rect class=\"stroke-span\" x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%s\" "
        "fill-opacity=\"0.12\"/><line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#888\" "
        "stroke-dasharray=\"3 2\"/><text x=\"%.1f\" y=\"%.1f\" font-size=\"9\" fill=\"#555\">%zu</text>\n",
        x_of(s.start_s), kTop, std::max(0.5, x_of(s.end_s) - x_of(s.start_s)), plot_h,
        s.completed ? "#2ca02c" : "#d62728", x_of(s.start_s), x_of(s.start_s), kTop, kTop + plot_h,
        x_of(s.start_s) + 2, kTop + 9, s.stroke + 1);
  }
  appendf(out, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#999\"/>\n",
          kLeft, kTop, plot_w, plot_h);
  // At most about two points per pixel column: the minimum and maximum of each bucket, so peaks survive.
  const std::size_t n = std::min(trial.time_s.size(), trial.in_plane_force_n.size());
  out += "<polyline fill=\"none\" stroke=\"#202020\" stroke-width=\"1\" points=\"";
  const std::size_t buckets = static_cast<std::size_t>(plot_w);
  for (std::size_t b = 0, begin = 0; b < buckets && begin < n; ++b) {
    const std::size_t end = std::max(begin + 1, (b + 1) * n / buckets);
    std::size_t lo = begin, hi = begin;
    for (std::size_t i = begin; i < end && i < n; ++i) {
      if (trial.in_plane_force_n[i] < trial.in_plane_force_n[lo]) lo = i;
      if (trial.in_plane_force_n[i] > trial.in_plane_force_n[hi]) hi = i;
    }
    for (const std::size_t i : {std::min(lo, hi), std::max(lo, hi)}) {
      appendf(out, "%.1f,%.1f ", x_of(trial.time_s[i]), y_of(trial.in_plane_force_n[i]));
    }
    begin = end;
  }
  out += "\"/>\n";
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\">%s N</text>\n", kLeft - 3,
          kTop + 8, number(f_max, 2).c_str());
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\">0</text>\n", kLeft - 3,
          kTop + plot_h);
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\">%s s</text>\n", kLeft, kHeight - 14,
          number(t0, 1).c_str());
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\">%s s</text>\n",
          kLeft + plot_w, kHeight - 14, number(t1, 1).c_str());
  appendf(out, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"middle\">time</text>\n",
          kLeft + plot_w / 2, kHeight - 4);
  out +=
      "</svg><figcaption>In-plane force |F<sub>xy</sub>| over time; shaded: each stroke from entering "
      "WS to its last feature point</figcaption></figure>\n";
}

void append_trial(std::string& out, const StudyReport& report, const ReportTrial& trial) {
  appendf(out,
          "<article class=\"trial\" data-subject=\"%s\" data-condition=\"%s\" data-phase=\"%s\">\n<h4>#%zu "
          "<span class=\"glyph\">%s</span> <span style=\"color:%s\">%s</span> %s r%d</h4>\n",
          escape(trial.subject).c_str(), escape(trial.condition).c_str(), escape(trial.phase).c_str(),
          trial.index, escape(trial.characters).c_str(), colour_of(report, trial.condition),
          escape(trial.condition).c_str(), escape(trial.phase).c_str(), trial.repetition);
  appendf(
      out,
      "<p class=\"metrics\">%s s &middot; deviation %s mm &middot; Fr&eacute;chet %s mm &middot; DTW %s mm "
      "&middot; order errors %zu &middot; backwards %zu",
      number(trial.time_total_s, 1).c_str(), number(trial.mean_deviation_mm, 2).c_str(),
      trial.frechet_mm ? number(*trial.frechet_mm, 2).c_str() : "&ndash;",
      trial.dtw_mm ? number(*trial.dtw_mm, 2).c_str() : "&ndash;", trial.order_errors,
      trial.backwards_strokes);
  if (trial.quiz_misses) appendf(out, " &middot; quiz misses %d", *trial.quiz_misses);
  if (!trial.completed) appendf(out, " &middot; <b>%s</b>", escape(trial.end_reason).c_str());
  out += "</p>\n<div class=\"figures\">\n";
  append_trajectory_figure(out, trial);
  append_force_figure(out, trial);
  out += "</div></article>\n";
}

constexpr const char* kStyle = R"(<style>
body{font-family:"Noto Sans","DejaVu Sans",sans-serif;margin:1.5em;color:#222;max-width:1600px}
h1{font-size:1.5em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}h3{margin-bottom:.3em}
table.summary{border-collapse:collapse;margin:.6em 1.2em .6em 0;display:inline-table;vertical-align:top}
table.summary td,table.summary th{border:1px solid #ccc;padding:.25em .5em}
table.summary caption{text-align:left;font-weight:bold;padding:.2em 0}
td.num{text-align:right;font-variant-numeric:tabular-nums}.n{color:#888;font-size:.85em}
figure{margin:.3em;display:inline-block;vertical-align:top}figcaption{font-size:.75em;color:#555;max-width:380px}
figure.trajectory figcaption{max-width:220px}
.trials{display:flex;flex-wrap:wrap;gap:.6em}
article.trial{flex:0 0 auto;width:620px;border:1px solid #ddd;border-radius:4px;padding:.3em .6em;background:#fafafa}
article.trial h4{margin:.2em 0}.glyph{font-size:1.3em}p.metrics{font-size:.8em;margin:.2em 0}
.figures{display:flex;flex-wrap:wrap;align-items:flex-start}
ul.sessions{font-size:.85em}
</style>
)";

}  // namespace

MeanSd mean_and_sd(std::span<const double> values) {
  MeanSd out;
  out.n = values.size();
  if (values.empty()) return out;
  double sum = 0.0;
  for (const double v : values) sum += v;
  out.mean = sum / static_cast<double>(values.size());
  if (values.size() >= 2) {
    double squares = 0.0;
    for (const double v : values) squares += (v - out.mean) * (v - out.mean);
    out.sd = std::sqrt(squares / static_cast<double>(values.size() - 1));
  }
  return out;
}

std::vector<double> measure_values(const StudyReport& report, ReportMeasure measure,
                                   const std::string& condition, std::optional<std::size_t> item,
                                   std::optional<int> repetition) {
  std::vector<double> values;
  for (const ReportTrial& trial : report.trials) {
    if (trial.phase != report.phase || trial.condition != condition) continue;
    if (item && trial.item != *item) continue;
    if (repetition && trial.repetition != *repetition) continue;
    if (const std::optional<double> value = value_of(trial, measure)) values.push_back(*value);
  }
  return values;
}

std::string study_report_html(const StudyReport& report) {
  std::string out;
  out.reserve(64 * 1024 + report.trials.size() * 24 * 1024);
  out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escape(report.title) +
         "</title>\n" + kStyle + "</head><body>\n<h1>" + escape(report.title) + "</h1>\n";
  std::size_t test_trials = 0;
  for (const ReportTrial& t : report.trials) test_trials += t.phase == report.phase ? 1 : 0;
  appendf(out, "<p>%zu sessions, %zu trials (%zu %s trials).</p>\n<ul class=\"sessions\">\n",
          report.sessions.size(), report.trials.size(), test_trials, escape(report.phase).c_str());
  for (const std::string& s : report.sessions) out += "<li>" + escape(s) + "</li>\n";
  out += "</ul>\n";
  for (const std::string& note : report.notes) out += "<p class=\"note\">" + escape(note) + "</p>\n";

  out += "<h2>Per condition (test trials)</h2>\n<section class=\"tables\">\n";
  for (const MeasureInfo& info : kMeasures) append_summary_table(out, report, info);
  out += "</section>\n<h3>Learning curves</h3>\n<section class=\"curves\">\n";
  append_learning_curve(out, report, kMeasures[0]);
  append_learning_curve(out, report, kMeasures[1]);
  out += "</section>\n<h2>Trials</h2>\n";
  std::string current;
  bool open = false;
  for (const ReportTrial& trial : report.trials) {
    const std::string key = trial.subject + "/" + trial.session;
    if (key != current) {
      if (open) out += "</div></section>\n";
      out += "<section class=\"session\"><h3>Subject " + escape(trial.subject) + " &mdash; " +
             escape(trial.session) + "</h3><div class=\"trials\">\n";
      current = key;
      open = true;
    }
    append_trial(out, report, trial);
  }
  if (open) out += "</div></section>\n";
  out += "</body></html>\n";
  return out;
}

}  // namespace calligraphy
