// The one metrics record of a written trace (writing_metrics.hpp, docs/metrics.md).
#include "calligraphy/analysis/writing_metrics.hpp"

#include <vector>

#include "analysis/durations.hpp"
#include "analysis/segmentation.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

void add_totals(WritingMetrics& metrics, const CharacterScore& score) {
  metrics.strokes_total += score.strokes.size();
  metrics.strokes_written += score.strokes_written;
  metrics.strokes_accepted += score.strokes_accepted;
  metrics.strokes_assisted += score.strokes_assisted;
  metrics.order_errors += score.order_errors;
  metrics.backwards_strokes += score.backwards_strokes;
  metrics.unmatched_segments += score.unmatched_strokes;
  for (const StrokeRefusal refusal :
       {StrokeRefusal::too_short, StrokeRefusal::backwards, StrokeRefusal::wrong_place,
        StrokeRefusal::wrong_stroke, StrokeRefusal::wrong_order}) {
    for (std::size_t k = score.refusals.of(refusal); k > 0; --k) metrics.refusals.add(refusal);
  }
}

}  // namespace

WritingMetrics writing_metrics(const Scene& scene, std::span<const PenSample> trace,
                               const ScoreOptions& options) {
  if (scene.characters.empty()) throw InvalidArgument("writing_metrics: the scene has no characters");
  validate_pen_trace(trace);
  ScoreOptions scored = options;
  scored.start_radius_m = scene.layout.start_radius_m;
  const std::vector<std::size_t> owner = trial_detail::character_of_samples(scene, trace);

  WritingMetrics metrics;
  metrics.completed_in_order = true;
  std::vector<DeviationSummary> deviations;
  double dtw_weighted = 0.0;
  double jerk_sum = 0.0;
  std::size_t jerk_count = 0;
  std::vector<PenSample> own(trace.begin(), trace.end());
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    for (std::size_t k = 0; k < trace.size(); ++k) own[k].pen_down = trace[k].pen_down && owner[k] == c;
    CharacterScore score = score_trace(scene.characters[c], own, scored);
    add_totals(metrics, score);
    metrics.completed_in_order = metrics.completed_in_order && score.completed_in_order;
    if (score.totals.deviation) {
      deviations.push_back(*score.totals.deviation);
      dtw_weighted += score.totals.dtw_m.value_or(0.0) * static_cast<double>(score.totals.deviation->samples);
      if (!metrics.frechet_m || score.totals.frechet_m.value_or(0.0) > *metrics.frechet_m)
        metrics.frechet_m = score.totals.frechet_m;
    }
    for (const WrittenSegment& segment : score.segments) {
      if (!segment.kinematics) continue;
      metrics.velocity_peaks += segment.kinematics->velocity_peaks;
      jerk_sum += segment.kinematics->normalised_jerk;
      ++jerk_count;
    }
    metrics.characters.push_back(std::move(score));
  }
  if (!deviations.empty()) {
    metrics.deviation = pool_deviation_summaries(deviations);
    metrics.dtw_m = dtw_weighted / static_cast<double>(metrics.deviation->samples);
  }
  if (jerk_count > 0) metrics.normalised_jerk = jerk_sum / static_cast<double>(jerk_count);

  // Times over the whole trace, whichever character a run belongs to.
  std::optional<double> first_down;
  double last_down = 0.0;
  for (std::size_t k = 0; k < trace.size(); ++k) {
    if (!trace[k].pen_down) continue;
    if (!first_down) first_down = trace[k].time_s;
    last_down = trace[k].time_s;
    if (k > 0 && trace[k - 1].pen_down) metrics.pen_down_time_s += trace[k].time_s - trace[k - 1].time_s;
  }
  if (first_down) metrics.total_time_s = analysis::whole_nanoseconds(last_down - *first_down);
  metrics.pen_down_time_s = analysis::whole_nanoseconds(metrics.pen_down_time_s);
  return metrics;
}

}  // namespace calligraphy
