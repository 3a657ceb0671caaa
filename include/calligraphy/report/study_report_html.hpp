#pragma once
/// \file study_report_html.hpp
/// One self-contained HTML page (inline SVG, no script, no external resource) for the trials of one or
/// more study sessions: per trial the pen trajectory over the reference (as the paper's Figs. 30-31 and
/// 37-38 show it) and the in-plane force over time with the strokes' spans (as Figs. 32-36); per condition
/// a table in the manner of the paper's Table 5 (mean and standard deviation over subjects and
/// repetitions of writing time, mean deviation, Frechet distance and order errors, per test character)
/// and learning curves over repetitions. Wang, Zhang & Yao 2006, Virtual Reality 9:118-132, section 7.
/// The study module reads session folders into a `StudyReport` (study/session_reader.hpp).
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// The time a stroke was written in a trial [s].
struct ReportStrokeSpan {
  std::size_t stroke = 0;  ///< 0-based over the trial's characters
  double start_s = 0.0;
  double end_s = 0.0;
  bool completed = false;
};

/// One trial as the report draws it. Lengths in metres, times in seconds, forces in newtons.
struct ReportTrial {
  std::string subject;
  std::string session;
  std::string phase;       ///< "practice" or "test"
  std::string condition;   ///< the condition's name
  std::string mode;        ///< the condition's mode ("vision", "haptic", ...)
  std::string characters;  ///< UTF-8
  std::string end_reason;  ///< TrialEnd as text
  std::size_t index = 0;   ///< 1-based position in its session
  std::size_t item = 0;    ///< 0-based index of the characters in the phase's list
  int repetition = 1;
  std::vector<std::vector<Vec2>> reference_m;  ///< one polyline per reference stroke, paper plane [m]
  std::vector<Vec2> stroke_starts_m;           ///< start point of each reference stroke [m]
  std::vector<double> time_s;                  ///< the trace, one entry per servo tick
  std::vector<Vec2> position_m;                ///< pen tip in the paper plane [m]
  std::vector<bool> pen_down;                  ///< the tip touched the paper
  std::vector<double> in_plane_force_n;        ///< |(Fx, Fy)| commanded [N]
  std::vector<ReportStrokeSpan> strokes;
  double time_total_s = 0.0;       ///< the trial's writing time [s]
  double mean_deviation_mm = 0.0;  ///< the trial's mean deviation [mm]; NaN when it wrote no stroke
  std::optional<double> frechet_mm;
  std::optional<double> dtw_mm;
  std::size_t order_errors = 0;
  std::size_t backwards_strokes = 0;
  bool completed = false;
  std::optional<int> quiz_misses;  ///< quiz conditions: strokes missed
};

/// What the page shows.
struct StudyReport {
  std::string title;
  std::vector<std::string> sessions;  ///< one line per session: subject, folder, protocol, device, writer
  /// The phase the tables and curves show: "test" (the paper's design), else "training".
  std::string phase = "test";
  std::vector<std::string> conditions;  ///< row order of the tables (the conditions of that phase)
  std::vector<std::string> items;  ///< that phase's characters in the protocol's order (UTF-8): C1, C2, ...
  std::vector<ReportTrial> trials;
  std::vector<std::string> notes;  ///< shown under the header (e.g. what a simulated subject is)
};

/// Mean and sample standard deviation (n - 1 in the denominator; NaN for n < 2).
struct MeanSd {
  std::size_t n = 0;
  double mean = std::numeric_limits<double>::quiet_NaN();
  double sd = std::numeric_limits<double>::quiet_NaN();
};
[[nodiscard]] MeanSd mean_and_sd(std::span<const double> values);

/// What a summary table or learning curve shows.
enum class ReportMeasure { time_s, mean_deviation_mm, frechet_mm, order_errors };

/// The values of `measure` over the test trials of `condition` (and of the test item `item` when given),
/// over subjects and repetitions. A trial without the value (no matched stroke for Frechet) is left out.
[[nodiscard]] std::vector<double> measure_values(const StudyReport& report, ReportMeasure measure,
                                                 const std::string& condition,
                                                 std::optional<std::size_t> item = std::nullopt,
                                                 std::optional<int> repetition = std::nullopt);

/// The page. Every text from the report is escaped; the page loads nothing.
[[nodiscard]] std::string study_report_html(const StudyReport& report);

}  // namespace calligraphy
