#pragma once
// Reports of a trial: the printed table, JSON (keys fixed by the CLI's contract), SVG and CSV.
#include <string>
#include <vector>

#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/trial/trial.hpp"

namespace calligraphy {

struct TrialDescription {
  std::string characters;  // UTF-8
  bool guidance = true;
  std::string writer;  ///< who wrote it: "simulated" or "person" (TrialSpec::writer's spelling)
  std::uint64_t seed = 0;
  double rate_hz = 1000.0;
  std::string device = "simulated";  // registry name
  std::string device_model = "Phantom Desktop (simulated)";
  // Provenance of the guidance and the simulated writer (each with a default, so that the fields above can
  // be given alone). In the JSON as "guidance_mode", "guidance_gain" (fading), "teacher" (replay),
  // "writer_profile" and "writer_parameters" (docs/cli.md).
  GuidanceMode guidance_mode = GuidanceMode::fixed;
  double guidance_gain = 1.0;                    ///< fading only
  std::string teacher_file{};                    ///< replay only: the recording's path
  std::string teacher_characters{};              ///< replay only: the characters it was recorded on
  std::string writer_profile{};                  ///< the simulated writer's profile; empty for a person
  std::vector<std::string> writer_parameters{};  ///< "key=value" settings applied to the profile
  /// The whole specification that ran, a JSON object (recorded_trial_json, trial/recorded_trial.hpp), kept
  /// in the JSON as "specification" so that `calligraphy trial --spec` runs it again; empty: none.
  std::string specification_json{};
};

/// The table of what was written (`writing`, the one metrics record: trial_writing_metrics, result.hpp), the
/// renderer's attempts and completions per stroke and its force figures, and a line saying why when the
/// trial was aborted. Strokes are numbered over the scene from 0.
void print_trial_table(const TrialDescription& d, const Scene& scene, const TrialResult& result,
                       const WritingMetrics& writing);
/// The trial as JSON: the description, how it ended (`end_reason`, `aborted`, `abort_reason`), the renderer's
/// figures (`strokes_completed`, `trial_time_s`, `max_force_n`, `max_force_step_n`, `state_transitions`,
/// `renderer_strokes`, `loop`) and every key of the one metrics record (`writing_metrics_json`,
/// score_report.hpp) with its values.
std::string trial_json(const TrialDescription& d, const TrialResult& result, const WritingMetrics& writing);
/// Reference in blue, pen trace in green, each stroke's start hint as a red ellipse (paper Figs. 30-31).
std::string trial_svg(const Scene& scene, const TrialResult& result);
/// Decimals of the trace's columns: t to 1 us (a 1 kHz servo tick is 1000 us), x, y, z to 0.1 um (far finer
/// than a Phantom Desktop's 0.023 mm encoder resolution; the simulated device's 1 um steps are kept
/// exactly), forces to 0.1 mN (guidance forces are tenths of a newton and more). A score of the file gives
/// the trial's own metrics to this precision (times within 0.5 us, lengths within 0.05 um).
inline constexpr int kTraceTimeDecimals = 6;
inline constexpr int kTracePositionDecimals = 7;
inline constexpr int kTraceForceDecimals = 4;
/// The trace, one row per tick: t,x,y,z,fx,fy,fz,state,stroke,element (SI units: s, m, N), each number with
/// the decimals above and no trailing zeros ("0.001", "-0.011845", "0").
std::string trial_csv(const std::vector<TrialSample>& trace);
/// Writes text to a file, whole or not at all (`write_file_atomically`, atomic_file.hpp); throws DataError
/// naming the path when it cannot.
void write_file(const std::string& path, const std::string& text);

}  // namespace calligraphy
