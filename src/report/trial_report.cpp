#include "calligraphy/report/trial_report.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <system_error>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/polyline.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/report/trace_columns.hpp"
#include "report/trial_outcome.hpp"

namespace calligraphy {
namespace {

// A length [m] in millimetres with `decimals` digits, or "-" when there is none.
std::string millimetres(const std::optional<double>& metres, int decimals) {
  if (!metres) return "-";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, *metres * 1e3);
  return text;
}

// The servo loop's statistics of a real-time trial, under the table.
void print_loop_statistics(const ServoLoopStats& loop) {
  std::printf("  servo loop                 %llu ticks, %llu late, %llu forces withheld\n",
              static_cast<unsigned long long>(loop.ticks), static_cast<unsigned long long>(loop.late_ticks),
              static_cast<unsigned long long>(loop.forces_withheld));
  std::printf("  longest stall              %.3f ms\n", loop.longest_stall_s * 1e3);
  std::printf("  period jitter p99 / max    %.0f / %.0f us (%s)\n", loop.period_jitter_us_p99,
              loop.period_jitter_us_max,
              loop.realtime.device_clock      ? "the device driver's servo thread"
              : loop.realtime.fifo_scheduling ? "SCHED_FIFO"
                                              : "normal scheduling, not SCHED_FIFO");
}

nlohmann::json loop_json(const ServoLoopStats& loop) {
  return {{"ticks", loop.ticks},
          {"late_ticks", loop.late_ticks},
          {"forces_withheld", loop.forces_withheld},
          {"longest_stall_ms", loop.longest_stall_s * 1e3},
          {"deadline_reanchors", loop.deadline_reanchors},
          {"period_jitter_us_p99", loop.period_jitter_us_p99},
          {"period_jitter_us_max", loop.period_jitter_us_max},
          {"fifo_scheduling", loop.realtime.fifo_scheduling},
          {"device_clock", loop.realtime.device_clock}};
}

}  // namespace

void print_trial_table(const TrialDescription& d, const Scene& scene, const TrialResult& result,
                       const WritingMetrics& writing) {
  (void)scene;
  const TrialMetrics& m = result.metrics;
  // The guidance as given: "on" (the paper's fixed fixture), "fading, gain G", "replay of TEACHER", "off".
  char guidance[512];
  if (!d.guidance) {
    std::snprintf(guidance, sizeof guidance, "off");
  } else if (d.guidance_mode == GuidanceMode::fading) {
    std::snprintf(guidance, sizeof guidance, "fading, gain %.3g", d.guidance_gain);
  } else if (d.guidance_mode == GuidanceMode::replay) {
    std::snprintf(guidance, sizeof guidance, "replay of %s",
                  d.teacher_file.empty() ? "a teacher" : d.teacher_file.c_str());
  } else if (d.guidance_mode == GuidanceMode::fixed) {
    std::snprintf(guidance, sizeof guidance, "on");
  } else {
    std::snprintf(guidance, sizeof guidance, "%s", to_string(d.guidance_mode));
  }
  std::printf(
      "Trial %s: guidance %s, writer %s, seed %llu, %.0f Hz, device %s (%s); strokes numbered from 1 "
      "here, from 0 in the JSON\n",
      d.characters.c_str(), guidance,
      (d.writer_profile.empty() ? d.writer : d.writer + " (" + d.writer_profile + ")").c_str(),
      static_cast<unsigned long long>(d.seed), d.rate_hz, d.device.c_str(), d.device_model.c_str());
  std::printf("\n  %-6s %-5s %-6s %-4s %9s %9s %11s %9s %9s %8s %9s\n", "stroke", "char", "type", "ID",
              "mean[mm]", "max[mm]", "Frechet[mm]", "DTW[mm]", "time[s]", "attempts", "completed");
  // Strokes numbered within their character from 1, as `score` and the trainer number them (the files count
  // from 0, as the renderer does); the renderer's per-stroke figures are over the scene.
  std::size_t scene_stroke = 0;
  for (const CharacterScore& character : writing.characters) {
    for (const StrokeScore& s : character.strokes) {
      const auto& w = s.metrics;
      const auto value = [&](auto member) { return w ? std::optional<double>(member(*w)) : std::nullopt; };
      const StrokeMetrics* live = scene_stroke < m.per_stroke.size() ? &m.per_stroke[scene_stroke] : nullptr;
      char time_text[32] = "-";
      if (w) std::snprintf(time_text, sizeof time_text, "%.2f", w->kinematics.writing_time_s);
      std::printf("  %-6zu %-5s %-6s %-4d %9s %9s %11s %9s %9s %8d %9s\n", s.index + 1,
                  encode_utf8(character.code_point).c_str(),
                  std::string(typical_stroke(s.typical_id).acronym).c_str(), s.typical_id,
                  millimetres(value([](auto& x) { return x.deviation.mean_m; }), 2).c_str(),
                  millimetres(value([](auto& x) { return x.deviation.max_m; }), 2).c_str(),
                  millimetres(value([](auto& x) { return x.curves.frechet_m; }), 2).c_str(),
                  millimetres(value([](auto& x) { return x.curves.dtw_m; }), 2).c_str(), time_text,
                  live ? live->attempts : 0,
                  live && live->completed ? "yes" : (live && live->assisted ? "assisted" : "no"));
      ++scene_stroke;
    }
  }
  const std::optional<double> mean =
      writing.deviation ? std::optional<double>(writing.deviation->mean_m) : std::nullopt;
  const std::optional<double> max =
      writing.deviation ? std::optional<double>(writing.deviation->max_m) : std::nullopt;
  // The renderer's count (`strokes_completed` of the JSON); the trial is incomplete only when a stroke was
  // neither taken nor credited as assisted. Whether the trace wrote every stroke in order is the writing's
  // `completed_in_order`, judged again below ("accepted in turn").
  std::printf("\n  strokes completed          %zu / %zu%s\n", m.strokes_completed, m.strokes_total,
              m.strokes_completed + m.strokes_assisted < m.strokes_total ? "  (incomplete)" : "");
  if (m.strokes_assisted > 0) std::printf("  strokes assisted           %zu\n", m.strokes_assisted);
  std::printf("  accepted in turn           %zu / %zu (order errors %zu, backwards %zu)\n",
              writing.strokes_accepted, writing.strokes_total, writing.order_errors,
              writing.backwards_strokes);
  // A trial stopped with the pen down: the scoring judges that last pen-down at the trace's end, as if lifted
  // there, where the renderer, which judges at a lift, gave it no verdict (docs/metrics.md).
  const bool judged_at_end =
      std::any_of(writing.characters.begin(), writing.characters.end(), [&](const auto& c) {
        return !c.segments.empty() && c.segments.back().end == result.trace.size() &&
               c.segments.back().verdict;
      });
  if (judged_at_end)
    std::printf("                             (the last pen-down judged at the trial's end, not lifted)\n");
  // "-" without a unit: nothing was written, so there is no deviation to give.
  std::printf("  mean deviation             %s%s\n", millimetres(mean, 3).c_str(), mean ? " mm" : "");
  std::printf("  max deviation              %s%s\n", millimetres(max, 3).c_str(), max ? " mm" : "");
  std::printf("  Frechet (worst stroke)     %s%s\n", millimetres(writing.frechet_m, 3).c_str(),
              writing.frechet_m ? " mm" : "");
  std::printf("  DTW (mean)                 %s%s\n", millimetres(writing.dtw_m, 3).c_str(),
              writing.dtw_m ? " mm" : "");
  // Named as `score` names the same trace's times: the total (first to last pen-down sample), then the
  // pen-down time, which docs/metrics.md calls the writing time.
  // "-": the pen never touched, so there is no first or last pen-down sample to time.
  char total_text[32] = "-";
  if (writing.total_time_s) std::snprintf(total_text, sizeof total_text, "%.2f s", *writing.total_time_s);
  std::printf("  time                       %s (pen down %.2f s)\n", total_text, writing.pen_down_time_s);
  std::printf("  trial time                 %.2f s\n", m.time_s);
  std::printf("  state transitions          %zu\n", m.state_transitions);
  std::printf("  max |F|                    %.3f N\n", m.max_force_n);
  std::printf("  max per-tick |dF|          %.3f N\n", m.max_force_step_n);
  if (m.readings_rejected > 0) std::printf("  readings rejected          %zu\n", m.readings_rejected);
  if (result.loop) print_loop_statistics(*result.loop);
  if (result.aborted) {
    std::printf("\n  ABORTED after %.3f s (%s)%s%s\n", m.time_s, to_string(result.end),
                result.abort_reason.empty() ? "" : ": ", result.abort_reason.c_str());
  }
}

std::string trial_json(const TrialDescription& d, const TrialResult& result, const WritingMetrics& writing) {
  // The renderer's view of each stroke (its attempts, whether it completed it in turn); what was written is
  // the one metrics record in the outcome.
  nlohmann::json renderer_strokes = nlohmann::json::array();
  for (const StrokeMetrics& s : result.metrics.per_stroke)
    renderer_strokes.push_back(report_detail::renderer_stroke_object(s));
  nlohmann::json doc = report_detail::trial_outcome_object(result, writing);
  doc.update({{"character", d.characters},
              {"guidance", d.guidance},
              {"writer", d.writer},
              {"seed", d.seed},
              {"rate_hz", d.rate_hz},
              {"device", d.device},
              {"device_time_at_start_s", result.device_time_at_start_s},
              {"renderer_strokes", renderer_strokes}});
  if (result.loop) doc["loop"] = loop_json(*result.loop);  // real-time trials only
  doc["guidance_mode"] = to_string(d.guidance_mode);
  if (d.guidance_mode == GuidanceMode::fading) doc["guidance_gain"] = d.guidance_gain;
  if (d.guidance_mode == GuidanceMode::replay)
    doc["teacher"] = {{"file", d.teacher_file}, {"characters", d.teacher_characters}};
  if (!d.writer_profile.empty()) doc["writer_profile"] = d.writer_profile;
  if (!d.writer_parameters.empty()) doc["writer_parameters"] = d.writer_parameters;
  // Made by its one writer above this module: parsed whole (a JSON number reads back to the same double).
  if (!d.specification_json.empty()) doc["specification"] = nlohmann::json::parse(d.specification_json);
  return json_text(doc, 2) + "\n";
}

std::string trial_svg(const Scene& scene, const TrialResult& result) {
  // Paper metres -> SVG pixels, y flipped (SVG y grows downwards).
  Eigen::AlignedBox2d box;
  for (const auto& c : scene.characters) box.extend(c.bounding_box);
  constexpr double kPixelsPerMetre = 8000.0;  // 60 mm -> 480 px
  const double margin = 0.01;
  const Vec2 lo = box.min() - Vec2(margin, margin);
  const Vec2 size = box.sizes() + Vec2(2 * margin, 2 * margin);
  const auto px = [&](const Vec2& p) {
    return Vec2((p.x() - lo.x()) * kPixelsPerMetre, (lo.y() + size.y() - p.y()) * kPixelsPerMetre);
  };
  std::ostringstream svg;
  svg.precision(2);
  svg << std::fixed;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size.x() * kPixelsPerMetre << "\" height=\""
      << size.y() * kPixelsPerMetre << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const auto& c : scene.characters) {  // reference strokes in blue
    for (const auto& s : c.strokes) {
      svg << "<polyline fill=\"none\" stroke=\"blue\" stroke-width=\"3\" stroke-linecap=\"round\" points=\"";
      for (const auto& e : s.elements) {
        for (const Vec2& p : sample_element(e, e.degree == 1 ? 1 : 24))
          svg << px(p).x() << "," << px(p).y() << " ";
      }
      svg << "\"/>\n";
    }
  }
  const auto& trace = result.trace;
  for (const StrokeMetrics& m :
       result.metrics.per_stroke) {  // pen trace in green, last attempt of each stroke
    if (m.trace_end <= m.trace_begin || m.trace_end > trace.size()) continue;
    svg << "<polyline fill=\"none\" stroke=\"limegreen\" stroke-width=\"1.5\" points=\"";
    // Points at least a pixel apart (and the last): the line looks the same in fewer bytes.
    svg.precision(1);
    Vec2 last(-1e9, -1e9);
    for (std::size_t i = m.trace_begin; i < m.trace_end; ++i) {
      const Vec2 p = px(trace[i].position_m.head<2>());
      if ((p - last).norm() < 1.0 && i + 1 < m.trace_end) continue;
      svg << p.x() << "," << p.y() << " ";
      last = p;
    }
    svg.precision(2);
    svg << "\"/>\n";
  }
  for (const auto& c : scene.characters) {  // start hints as red ellipses
    for (const auto& s : c.strokes) {
      const Vec2 p = px(s.start());
      const double r = scene.layout.start_radius_m * kPixelsPerMetre;
      svg << "<ellipse cx=\"" << p.x() << "\" cy=\"" << p.y() << "\" rx=\"" << r << "\" ry=\"" << 0.7 * r
          << "\" fill=\"none\" stroke=\"red\" stroke-width=\"1.5\"/>\n";
    }
  }
  svg << "</svg>\n";
  return svg.str();
}

namespace {

// `value` with `decimals` decimals, trailing zeros (and a bare point) dropped, "-0" written "0": a fixed
// precision in the fewest characters.
char* fixed(char* out, char* end, double value, int decimals) {
  char* const start = out;
  // Beyond 1e15 (no device reports such a value; a fault might) and NaN: the shortest round-trip text,
  // so that a row stays within its buffer.
  if (!(std::abs(value) < 1e15)) return std::to_chars(out, end, value).ptr;
  const auto [ptr, error] = std::to_chars(out, end, value, std::chars_format::fixed, decimals);
  if (error != std::errc{}) return out;
  out = ptr;
  if (decimals > 0) {
    while (out[-1] == '0') --out;
    if (out[-1] == '.') --out;
  }
  if (out - start == 2 && start[0] == '-' && start[1] == '0') {
    start[0] = '0';
    out = start + 1;
  }
  return out;
}

}  // namespace

std::string trial_csv(const std::vector<TrialSample>& trace) {
  std::string csv;
  for (const TraceColumnInfo& column : trace_columns()) {  // the one table's file names, in its order
    csv += csv.empty() ? "" : ",";
    csv += column.file_name;
  }
  csv += '\n';
  csv.reserve(csv.size() + trace.size() * 64);
  char line[512];
  for (const TrialSample& s : trace) {
    char* out = line;
    char* const end = line + sizeof line;
    const auto field = [&](double value, int decimals) {
      out = fixed(out, end, value, decimals);
      *out++ = ',';
    };
    field(s.time_s, kTraceTimeDecimals);
    for (int axis = 0; axis < 3; ++axis) field(s.position_m[axis], kTracePositionDecimals);
    for (int axis = 0; axis < 3; ++axis) field(s.force_n[axis], kTraceForceDecimals);
    out += std::snprintf(out, static_cast<std::size_t>(end - out), "%s,%zu,%zu,%d,%d\n", to_string(s.state),
                         s.stroke, s.element, s.attempt, s.rewritten ? 1 : 0);
    csv.append(line, out);
  }
  return csv;
}

void write_file(const std::string& path, const std::string& text) { write_file_atomically(path, text); }

}  // namespace calligraphy
