#pragma once
/// \file study_report_html.hpp
/// The per-trial pages of saved study sessions (HTML with inline SVG, no script, nothing loaded): per
/// trial the pen trajectory over the reference (as the paper's Figs. 30-31 and 37-38 show it), the
/// in-plane force over time with the strokes' spans (as Figs. 32-36) and the trial's own values. Wang,
/// Zhang & Yao 2006, Virtual Reality 9:118-132, section 7. No summary over trials: the study's summaries
/// and statistics are the Python report's (`python3 -m calligraphy.study_report`, docs/experiments.md),
/// which links here for each trial.
///
/// One page per session, `NAME_files/SUBJECT/SESSION.html` beside an index page `NAME.html` that lists the
/// sessions; each trial is an `<article>` with the id `trial-SESSION-N` (N its 1-based number in the
/// session), so `NAME_files/SUBJECT/SESSION.html#trial-SESSION-N` shows one trial. A session's page is
/// built as its trials are read, so a study of any size is never held whole (the study module reads the
/// folders: study/session_reader.hpp).
#include <cstddef>
#include <optional>
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

/// One trial as its page draws it. Lengths in metres, times in seconds, forces in newtons.
struct ReportTrial {
  std::string subject;
  std::string session;     ///< the session id (its folder's name)
  std::string phase;       ///< "practice", "test", "pre-test", "training", ...
  std::string condition;   ///< the condition's name
  std::string mode;        ///< the condition's mode ("vision", "haptic", ...)
  std::string characters;  ///< UTF-8
  std::string end_reason;  ///< TrialEnd as text
  std::size_t index = 1;   ///< 1-based number of the trial in its session (its file's NNN)
  std::size_t block = 1;   ///< 1-based block of the session's plan
  std::size_t item = 1;    ///< 1-based position of the characters in the phase's list
  int repetition = 1;      ///< 1-based repetition of the item in the condition
  std::vector<std::vector<Vec2>> reference_m;  ///< one polyline per reference stroke, paper plane [m]
  std::vector<Vec2> stroke_starts_m;           ///< start point of each reference stroke [m]
  std::vector<double> time_s;                  ///< the trace, one entry per servo tick
  std::vector<Vec2> position_m;                ///< pen tip in the paper plane [m]
  std::vector<bool> pen_down;                  ///< the tip touched the paper
  std::vector<double> in_plane_force_n;        ///< |(Fx, Fy)| commanded [N]
  std::vector<ReportStrokeSpan> strokes;
  double time_total_s = 0.0;        ///< the trial's writing time [s]; NaN when the pen never touched
  double mean_deviation_m = 0.0;    ///< the trial's mean deviation [m]; NaN when it wrote no stroke
  std::optional<double> frechet_m;  ///< [m]
  std::optional<double> dtw_m;      ///< [m]
  std::size_t order_errors = 0;
  std::size_t backwards_strokes = 0;
  bool completed = false;
  std::optional<int> quiz_misses;  ///< quiz conditions: strokes missed
  /// Quiz conditions: strokes the quiz credited assisted (0 in records written before it did).
  int quiz_assisted = 0;
};

/// One session as the index lists it and its page heads it.
struct ReportSession {
  std::string subject;
  std::string session;                  ///< the session id (its folder's name)
  std::string description;              ///< one line: folder, protocol, device, writer, trials saved, library
  std::string group;                    ///< the subject's between-subjects group; "" when none
  std::size_t saved = 0;                ///< trials saved
  std::size_t planned = 0;              ///< trials planned
  std::vector<std::string> conditions;  ///< the protocol's conditions, in its order (their colours)
};

/// What the index page shows.
struct StudyReportIndex {
  std::string title;
  std::vector<ReportSession> sessions;
  std::vector<std::string> notes;  ///< shown under the header (e.g. what the simulated subjects were)
};

/// "trial-SESSION-N": the HTML id of trial `number` (1-based) of `session` on its page.
[[nodiscard]] std::string trial_anchor(const std::string& session, std::size_t number);

/// "NAME_files": the folder of the session pages beside the index page `index_name` ("NAME.html").
[[nodiscard]] std::string session_pages_folder(const std::string& index_name);

/// "NAME_files/SUBJECT/SESSION.html": where a session's page is, relative to the folder of the index page
/// `index_name` ("NAME.html", or a name without ".html").
[[nodiscard]] std::string session_page_path(const std::string& index_name, const std::string& subject,
                                            const std::string& session);

/// The index page: the title, notes and a table of the sessions, each linked to its page
/// (`session_page_path`). Every text is escaped.
[[nodiscard]] std::string study_index_html(const StudyReportIndex& index, const std::string& index_name);

/// A session's page, built one trial at a time: memory holds the page's text and one trial.
class SessionPageHtml {
 public:
  /// `index_href`: the index page, relative to this page (a link back).
  SessionPageHtml(const ReportSession& session, const std::string& title, const std::string& index_href);
  /// Appends the trial's article: its heading, values, trajectory and force figures.
  void add(const ReportTrial& trial);
  /// The page; the object is spent.
  [[nodiscard]] std::string finish();
  [[nodiscard]] std::size_t trials() const { return trials_; }

 private:
  std::string out_;
  std::vector<std::string> conditions_;
  std::size_t trials_ = 0;
};

}  // namespace calligraphy
