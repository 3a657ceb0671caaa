#include "report/trial_outcome.hpp"

#include "report/metrics_object.hpp"

namespace calligraphy::report_detail {

MetricValue run_metric_value(const MetricInfo& info, const TrialMetrics& m) {
  // The run's figures of the metric table (metric_level_run), each from the renderer's TrialMetrics.
  const auto count = [](std::size_t value) { return MetricValue(static_cast<std::int64_t>(value)); };
  if (info.name == "strokes_completed") return count(m.strokes_completed);
  if (info.name == "strokes_assisted") return count(m.strokes_assisted);
  if (info.name == "trial_time_s") return MetricValue(m.time_s);
  if (info.name == "max_force_n") return MetricValue(m.max_force_n);
  if (info.name == "max_force_step_n") return MetricValue(m.max_force_step_n);
  if (info.name == "state_transitions") return count(m.state_transitions);
  if (info.name == "readings_rejected") return count(m.readings_rejected);
  return std::monostate{};
}

nlohmann::json trial_outcome_object(const TrialResult& result, const WritingMetrics& writing) {
  nlohmann::json record = writing_metrics_object(writing);
  record["end_reason"] = to_string(result.end);
  record["aborted"] = result.aborted;
  record["abort_reason"] = result.abort_reason;
  for (const MetricInfo& info : metric_table()) {
    if (info.at(metric_level_run))
      record[std::string(info.name)] = metric_json(run_metric_value(info, result.metrics));
  }
  return record;
}

nlohmann::json renderer_stroke_object(const StrokeMetrics& stroke) {
  return {{"index", stroke.index},         {"character", stroke.character}, {"typical_id", stroke.typical_id},
          {"completed", stroke.completed}, {"assisted", stroke.assisted},   {"attempts", stroke.attempts}};
}

}  // namespace calligraphy::report_detail
