// The per-trial pages of a study (study_report_html.hpp): per trial its figures as inline SVG and its
// own values; an index of the sessions.
#include "calligraphy/report/study_report_html.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "report/appendf.hpp"
#include "report/markup_escape.hpp"

namespace calligraphy {
namespace {

// Okabe & Ito's colour-blind-safe palette (Okabe & Ito 2008, "Color Universal Design"), one colour per
// condition in the protocol's order.
constexpr std::array<const char*, 7> kConditionColours{"#0072B2", "#E69F00", "#009E73", "#CC79A7",
                                                       "#56B4E9", "#D55E00", "#000000"};

std::string number(double value, int decimals) {
  if (!std::isfinite(value)) return "&ndash;";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

const char* colour_of(const std::vector<std::string>& conditions, const std::string& condition) {
  const auto found = std::find(conditions.begin(), conditions.end(), condition);
  const auto index = static_cast<std::size_t>(found - conditions.begin());
  return kConditionColours[index % kConditionColours.size()];
}

// A path for an href: each byte outside RFC 3986's unreserved characters and '/' percent-encoded.
std::string href(const std::string& path) {
  std::string out;
  for (const char c : path) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isalnum(byte) != 0 || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      out += c;
    } else {
      appendf(out, "%%%02X", byte);
    }
  }
  return out;
}

// ---- Per-trial figures -------------------------------------------------------------------------

// "x,y " with one decimal: a polyline's point (to_chars: the figures of a study have millions of points).
void append_point(std::string& out, const Vec2& p) {
  char text[64];
  char* end = text + sizeof text;
  char* at = std::to_chars(text, end, p.x(), std::chars_format::fixed, 1).ptr;
  *at++ = ',';
  at = std::to_chars(at, end, p.y(), std::chars_format::fixed, 1).ptr;
  *at++ = ' ';
  out.append(text, at);
}

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
          "height=\"%.0f\" viewBox=\"0 0 %.1f %.1f\" role=\"img\"><title>Trial %zu, %s: trajectory over the "
          "reference</title><rect width=\"100%%\" height=\"100%%\" fill=\"#fff\"/>\n",
          width_px, height_px, width_px, height_px, trial.index, escape_markup(trial.characters).c_str());
  for (const auto& stroke : trial.reference_m) {
    out +=
        "<polyline fill=\"none\" stroke=\"#3060d0\" stroke-opacity=\"0.6\" stroke-width=\"5\" "
        "stroke-linecap=\"round\" stroke-linejoin=\"round\" points=\"";
    for (const Vec2& p : stroke) append_point(out, px(p));
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
    append_point(out, px(p));
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
  appendf(
      out,
      "<figure class=\"force\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "viewBox=\"0 0 %.0f %.0f\" role=\"img\"><title>Trial %zu, %s: in-plane force over time</title><rect "
      "width=\"100%%\" height=\"100%%\" fill=\"#fff\"/>\n",
      kWidth, kHeight, kWidth, kHeight, trial.index, escape_markup(trial.characters).c_str());
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
      append_point(out, Vec2(x_of(trial.time_s[i]), y_of(trial.in_plane_force_n[i])));
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

void append_trial(std::string& out, const std::vector<std::string>& conditions, const ReportTrial& trial) {
  appendf(out,
          "<article class=\"trial\" id=\"%s\" data-subject=\"%s\" data-condition=\"%s\" "
          "data-phase=\"%s\">\n<h4><a href=\"#%s\">#%zu</a> <span class=\"glyph\">%s</span> %s <span "
          "style=\"color:%s\">%s</span> block %zu, item %zu, r%d</h4>\n",
          escape_markup(trial_anchor(trial.session, trial.index)).c_str(),
          escape_markup(trial.subject).c_str(), escape_markup(trial.condition).c_str(),
          escape_markup(trial.phase).c_str(),
          escape_markup(href(trial_anchor(trial.session, trial.index))).c_str(), trial.index,
          escape_markup(trial.characters).c_str(), escape_markup(trial.phase).c_str(),
          colour_of(conditions, trial.condition), escape_markup(trial.condition).c_str(), trial.block,
          trial.item, trial.repetition);
  appendf(
      out,
      "<p class=\"metrics\">%s s &middot; deviation %s mm &middot; Fr&eacute;chet %s mm &middot; DTW %s mm "
      "&middot; order errors %zu &middot; backwards %zu",
      number(trial.time_total_s, 1).c_str(), number(trial.mean_deviation_m * 1e3, 2).c_str(),
      trial.frechet_m ? number(*trial.frechet_m * 1e3, 2).c_str() : "&ndash;",
      trial.dtw_m ? number(*trial.dtw_m * 1e3, 2).c_str() : "&ndash;", trial.order_errors,
      trial.backwards_strokes);
  if (trial.quiz_misses) appendf(out, " &middot; quiz misses %d", *trial.quiz_misses);
  if (trial.quiz_assisted > 0) appendf(out, " &middot; quiz strokes assisted %d", trial.quiz_assisted);
  if (!trial.completed) appendf(out, " &middot; <b>%s</b>", escape_markup(trial.end_reason).c_str());
  out += "</p>\n<div class=\"figures\">\n";
  append_trajectory_figure(out, trial);
  append_force_figure(out, trial);
  out += "</div></article>\n";
}

constexpr const char* kStyle = R"(<style>
body{font-family:"Noto Sans","DejaVu Sans",sans-serif;margin:1.5em;color:#222;max-width:1600px}
h1{font-size:1.5em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}h3{margin-bottom:.3em}
table.sessions{border-collapse:collapse;font-size:.85em}
table.sessions td,table.sessions th{border:1px solid #ccc;padding:.25em .5em;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:.3em;display:inline-block;vertical-align:top}figcaption{font-size:.75em;color:#555;max-width:380px}
figure.trajectory figcaption{max-width:220px}
.trials{display:flex;flex-wrap:wrap;gap:.6em}
article.trial{flex:0 0 auto;width:620px;border:1px solid #ddd;border-radius:4px;padding:.3em .6em;background:#fafafa}
article.trial h4{margin:.2em 0}.glyph{font-size:1.3em}p.metrics{font-size:.8em;margin:.2em 0}
.figures{display:flex;flex-wrap:wrap;align-items:flex-start}
article.trial:target{border-color:#0072B2;box-shadow:0 0 0 2px #0072B2}
</style>
)";

void append_head(std::string& out, const std::string& title) {
  out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escape_markup(title) +
         "</title>\n" + kStyle + "</head><body>\n";
}

}  // namespace

std::string trial_anchor(const std::string& session, std::size_t number) {
  return "trial-" + session + "-" + std::to_string(number);
}

std::string session_pages_folder(const std::string& index_name) {
  std::string stem = index_name;
  if (stem.size() > 5 && stem.ends_with(".html")) stem.resize(stem.size() - 5);
  return stem + "_files";
}

std::string session_page_path(const std::string& index_name, const std::string& subject,
                              const std::string& session) {
  return session_pages_folder(index_name) + "/" + subject + "/" + session + ".html";
}

std::string study_index_html(const StudyReportIndex& index, const std::string& index_name) {
  std::string out;
  append_head(out, index.title);
  out += "<h1>" + escape_markup(index.title) + "</h1>\n";
  std::size_t saved = 0;
  for (const ReportSession& s : index.sessions) saved += s.saved;
  appendf(out,
          "<p>%zu session%s, %zu trial%s: one page per session, each trial's trajectory over the reference, "
          "its force over time and its own values. The study's summaries and statistics are the study "
          "report's (<code>python3 -m calligraphy.study_report</code>).</p>\n",
          index.sessions.size(), index.sessions.size() == 1 ? "" : "s", saved, saved == 1 ? "" : "s");
  for (const std::string& note : index.notes) out += "<p class=\"note\">" + escape_markup(note) + "</p>\n";
  out +=
      "<table class=\"sessions\">\n<tr><th>Subject</th><th>Group</th><th>Session</th><th>Trials saved</th>"
      "<th>Details</th></tr>\n";
  for (const ReportSession& s : index.sessions) {
    appendf(out,
            "<tr><td>%s</td><td>%s</td><td><a href=\"%s\">%s</a></td><td class=\"num\">%zu of "
            "%zu</td><td>%s</td></tr>\n",
            escape_markup(s.subject).c_str(),
            s.group.empty() ? "none (no between-subjects phase)" : escape_markup(s.group).c_str(),
            escape_markup(href(session_page_path(index_name, s.subject, s.session))).c_str(),
            escape_markup(s.session).c_str(), s.saved, s.planned, escape_markup(s.description).c_str());
  }
  out += "</table>\n</body></html>\n";
  return out;
}

SessionPageHtml::SessionPageHtml(const ReportSession& session, const std::string& title,
                                 const std::string& index_href)
    : conditions_(session.conditions) {
  append_head(out_, title + ": " + session.session);
  out_ += "<p><a href=\"" + escape_markup(href(index_href)) + "\">" + escape_markup(title) +
          "</a></p>\n<h1>Subject " + escape_markup(session.subject) + " &mdash; " +
          escape_markup(session.session) + "</h1>\n<p>" + escape_markup(session.description) +
          "</p>\n<div class=\"trials\">\n";
}

void SessionPageHtml::add(const ReportTrial& trial) {
  append_trial(out_, conditions_, trial);
  ++trials_;
}

std::string SessionPageHtml::finish() {
  out_ += "</div>\n</body></html>\n";
  return std::move(out_);
}

}  // namespace calligraphy
