#include "report/trial_outcome.hpp"

#include "report/metrics_object.hpp"

namespace calligraphy::report_detail {

nlohmann::json trial_outcome_object(const TrialResult& result, const WritingMetrics& writing) {
  const TrialMetrics& m = result.metrics;
  nlohmann::json record = writing_metrics_object(writing);
  record["end_reason"] = to_string(result.end);
  record["aborted"] = result.aborted;
  record["abort_reason"] = result.abort_reason;
  record["strokes_completed"] = m.strokes_completed;
  record["strokes_assisted"] = m.strokes_assisted;
  record["trial_time_s"] = m.time_s;
  record["max_force_n"] = m.max_force_n;
  record["max_force_step_n"] = m.max_force_step_n;
  record["state_transitions"] = m.state_transitions;
  return record;
}

nlohmann::json renderer_stroke_object(const StrokeMetrics& stroke) {
  return {{"index", stroke.index},         {"character", stroke.character}, {"typical_id", stroke.typical_id},
          {"completed", stroke.completed}, {"assisted", stroke.assisted},   {"attempts", stroke.attempts}};
}

}  // namespace calligraphy::report_detail
