#pragma once
// The JSON record of one study trial: results, scores and full provenance (format: docs/experiments.md).
// Internal.
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/sim/writer_memory.hpp"
#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy::study_detail {

/// Everything a trial record names besides the result.
struct TrialRecordContext {
  const SessionManifest* session = nullptr;
  const PlannedTrial* trial = nullptr;
  const StudyCondition* condition = nullptr;
  const TrialOptions* options = nullptr;
  /// The specification that ran (with `options` and the writer, the record's "specification":
  /// recorded_trial.hpp); nullptr: the record holds none.
  const TrialSpec* spec = nullptr;
  std::string device_name;
  DeviceInfo device_info;
  bool hardware = false;
  bool simulated_writer = false;
  SimulationOptions simulation;  ///< the simulated writer and its seed, when `simulated_writer`
  std::string start_utc;
  std::string end_utc;
  double wall_time_s = 0.0;
  nlohmann::json guidance;  ///< the "guidance" object (trial_guidance.hpp); null: none
  /// A learning simulated writer's skills before the trial (writer_memory.hpp); none: nullopt.
  std::optional<WriterSkills> writer_skills;
  /// What the simulated writer did (its log): attempts, refusals, strokes not taken, strokes given up.
  std::optional<WriterLog> writer_log;
  std::string csv_file;    ///< file names beside the JSON, each empty when not written: the trace as CSV,
  std::string trace_file;  ///< the trace as HDF5 (trace_hdf5.hpp),
  std::string svg_file;    ///< the drawing
  /// Lower-case hex SHA-256 (FIPS 180-4) of the trace file's bytes as saved, so that a reader draws and
  /// analyses this trial's trace and no other (files.trace_sha256); empty: not written.
  std::string trace_sha256;
};

/// The stroke matcher's tolerances as a JSON object by their table's names (corridor_m, mean_deviation_m,
/// ...; ParameterTable<StrokeAcceptance>), the names a protocol's quiz condition reads them by: the record's
/// force.acceptance and quiz.acceptance, and its specification's force_law.acceptance.
nlohmann::json acceptance_json(const StrokeAcceptance& acceptance);

/// The record: the context, the renderer's figures and every key of the one metrics record `writing`
/// (trial_writing_metrics). `quiz` is given for quiz conditions.
nlohmann::json trial_record(const TrialRecordContext& context, const Scene& scene, const TrialResult& result,
                            const WritingMetrics& writing, const std::vector<std::vector<QuizEvent>>* quiz);

/// `trial_record` as JSON text (2-space indent): the context, the renderer's figures and every key of the one
/// metrics record `writing` (trial_writing_metrics). `quiz` is given for quiz conditions.
std::string trial_record_json(const TrialRecordContext& context, const Scene& scene,
                              const TrialResult& result, const WritingMetrics& writing,
                              const std::vector<std::vector<QuizEvent>>* quiz);

}  // namespace calligraphy::study_detail
