#pragma once
// The JSON record of one study trial: results, scores and full provenance (format: docs/experiments.md).
// Internal.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/study/quiz.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/score.hpp"

namespace calligraphy::study_detail {

/// Everything a trial record names besides the result.
struct TrialRecordContext {
  const SessionManifest* session = nullptr;
  const PlannedTrial* trial = nullptr;
  const StudyCondition* condition = nullptr;
  const TrialOptions* options = nullptr;
  std::string device_name;
  DeviceInfo device_info;
  bool hardware = false;
  bool simulated_writer = false;
  std::string start_utc;
  std::string end_utc;
  double wall_time_s = 0.0;
  nlohmann::json guidance;  ///< the "guidance" object (trial_guidance.hpp); null: none
  std::string csv_file;     ///< file names beside the JSON
  std::string svg_file;
};

/// The stroke matcher's tolerances as a JSON object, by the names a protocol's quiz condition reads them
/// by (corridor_m, mean_deviation_m, ...): the record's force.acceptance and quiz.acceptance.
nlohmann::json acceptance_json(const StrokeAcceptance& acceptance);

/// The pen samples of `trace` while character `character` of `scene` was the active one: pen down when
/// the tip is within the contact threshold of `calligraphy score` (PenTraceCsvOptions) above the paper.
std::vector<PenSample> pen_samples_of_character(const Scene& scene, const std::vector<TrialSample>& trace,
                                                std::size_t character);

/// The score of each character of the scene against its part of the trace, its segment verdicts with the
/// trial's stroke `acceptance` and the scene's start radius: the renderer's.
std::vector<CharacterScore> score_characters(const Scene& scene, const std::vector<TrialSample>& trace,
                                             const StrokeAcceptance& acceptance);

/// The quiz events of each character, the trace fed through a `QuizSession` per character.
std::vector<std::vector<QuizEvent>> quiz_characters(const Scene& scene, const std::vector<TrialSample>& trace,
                                                    const QuizOptions& options);

/// The record as JSON text (2-space indent). `quiz` is given for quiz conditions.
std::string trial_record_json(const TrialRecordContext& context, const Scene& scene,
                              const TrialResult& result, const std::vector<CharacterScore>& scores,
                              const std::vector<std::vector<QuizEvent>>* quiz);

}  // namespace calligraphy::study_detail
