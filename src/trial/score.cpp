#include "calligraphy/trial/score.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "trial/assignment.hpp"
#include "trial/input_checks.hpp"
#include "trial/segmentation.hpp"
#include "trial/stroke_match.hpp"

namespace calligraphy {
namespace {

std::string character_name(char32_t code_point) {
  char text[16];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(code_point));
  return text;
}

void check_options(const ScoreOptions& options) {
  if (!std::isfinite(options.leniency) || options.leniency <= 0.0) {
    throw InvalidArgument("ScoreOptions: leniency " + std::to_string(options.leniency) +
                          " is not finite and > 0");
  }
  if (!std::isfinite(options.min_segment_length_m) || options.min_segment_length_m < 0.0) {
    throw InvalidArgument("ScoreOptions: minimum segment length " +
                          std::to_string(options.min_segment_length_m) + " m is not finite and >= 0");
  }
  trial_detail::require_valid_options(options.metrics);
}

// The reference of the match tests: the stroke's median in data units (what Hanzi Writer matches against),
// or the element joints when the stroke was placed without one.
trial_detail::MatchCurve reference_curve(const PlacedStroke& stroke, const Placement& placement) {
  std::vector<Vec2> points;
  if (stroke.median_m.size() >= 2) {
    for (const Vec2& p : stroke.median_m) points.push_back(placement.to_data(p));
  } else {
    points.push_back(placement.to_data(stroke.start()));
    for (const StrokeElement& e : stroke.elements) points.push_back(placement.to_data(e.end()));
  }
  return trial_detail::reference_match_curve(points);
}

// Pairs (i < j) with sequence[i] > sequence[j].
std::size_t inversions(const std::vector<std::size_t>& sequence) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    for (std::size_t j = i + 1; j < sequence.size(); ++j) count += sequence[i] > sequence[j] ? 1 : 0;
  }
  return count;
}

// Timing of all pen-down segments and kinematics of the scored ones.
void add_timing(CharacterScore& score, std::span<const PenSample> trace) {
  CharacterWritingMetrics& totals = score.totals;
  const auto& segments = score.segments;
  double jerk_sum = 0.0;
  std::size_t jerk_count = 0;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const WrittenSegment& s = segments[k];
    totals.writing_time_s += trace[s.end - 1].time_s - trace[s.begin].time_s;
    for (std::size_t i = s.begin + 1; i < s.end; ++i)
      totals.path_length_m += (trace[i].position_m - trace[i - 1].position_m).norm();
    if (k > 0) totals.in_air_time_s += trace[s.begin].time_s - trace[segments[k - 1].end - 1].time_s;
    if (s.kinematics) {
      totals.velocity_peaks += s.kinematics->velocity_peaks;
      jerk_sum += s.kinematics->normalised_jerk;
      ++jerk_count;
    }
  }
  if (!segments.empty()) {
    totals.pen_lifts = segments.size() - 1;
    totals.total_time_s = trace[segments.back().end - 1].time_s - trace[segments.front().begin].time_s;
  }
  if (totals.writing_time_s > 0.0) totals.mean_speed_m_per_s = totals.path_length_m / totals.writing_time_s;
  if (jerk_count > 0) totals.normalised_jerk = jerk_sum / static_cast<double>(jerk_count);
}

void add_spatial_totals(CharacterScore& score) {
  std::vector<DeviationSummary> parts;
  double dtw_weighted = 0.0;
  double frechet_max = 0.0;
  for (const StrokeScore& s : score.strokes) {
    if (!s.metrics) continue;
    parts.push_back(s.metrics->deviation);
    dtw_weighted += s.metrics->curves.dtw_m * static_cast<double>(s.metrics->deviation.samples);
    frechet_max = std::max(frechet_max, s.metrics->curves.frechet_m);
  }
  if (parts.empty()) return;
  score.totals.deviation = pool_deviation_summaries(parts);
  score.totals.frechet_m = frechet_max;
  score.totals.dtw_m = dtw_weighted / static_cast<double>(score.totals.deviation->samples);
}

}  // namespace

double closer_stroke_leniency_factor(double closer_distance, double own_distance) noexcept {
  if (!(own_distance > 0.0)) return 1.0;
  return 0.6 * (closer_distance + own_distance) / (2.0 * own_distance);
}

CharacterScore score_trace(const PlacedCharacter& character, std::span<const PenSample> trace,
                           const ScoreOptions& options) {
  check_options(options);
  if (character.strokes.empty()) {
    throw InvalidArgument("score_trace: character " + character_name(character.code_point) +
                          " has no stroke");
  }
  const Placement& placement = character.placement;
  if (!placement.origin_m.allFinite() || !std::isfinite(placement.metres_per_unit) ||
      !(placement.metres_per_unit > 0.0)) {
    throw InvalidArgument("score_trace: character " + character_name(character.code_point) +
                          " has a placement that is not finite with a positive scale");
  }
  for (std::size_t r = 0; r < character.strokes.size(); ++r) {
    if (character.strokes[r].elements.empty()) {
      throw InvalidArgument("score_trace: stroke " + std::to_string(r) + " of character " +
                            character_name(character.code_point) + " has no element");
    }
  }
  validate_pen_trace(trace);

  CharacterScore score;
  score.code_point = character.code_point;
  for (std::size_t r = 0; r < character.strokes.size(); ++r) {
    StrokeScore s;
    s.index = r;
    s.typical_id = character.strokes[r].typical_id;
    score.strokes.push_back(s);
  }
  score.segments =
      trial_detail::pen_down_segments(trace, options.min_segment_samples, options.min_segment_length_m);

  // Samples, kinematics and match curves of the scored segments.
  std::vector<std::size_t> scored;  // indices into score.segments
  std::vector<std::vector<double>> times;
  std::vector<std::vector<Vec2>> positions;
  std::vector<trial_detail::MatchCurve> written;
  for (std::size_t k = 0; k < score.segments.size(); ++k) {
    WrittenSegment& segment = score.segments[k];
    if (segment.ignored) {
      ++score.ignored_segments;
      continue;
    }
    std::vector<double> t;
    std::vector<Vec2> p;
    std::vector<Vec2> data;
    for (std::size_t i = segment.begin; i < segment.end; ++i) {
      t.push_back(trace[i].time_s);
      p.push_back(trace[i].position_m);
      data.push_back(placement.to_data(trace[i].position_m));
      if (!data.back().allFinite()) {
        throw InvalidArgument("score_trace: sample " + std::to_string(i) +
                              " is too far away to convert to data units");
      }
    }
    segment.kinematics = stroke_kinematics(t, p, options.metrics.kinematics);
    scored.push_back(k);
    times.push_back(std::move(t));
    positions.push_back(std::move(p));
    written.push_back(trial_detail::written_match_curve(data));
  }

  // Hanzi Writer's tests for every (reference stroke, scored segment) pair, then a one-to-one assignment.
  const std::size_t strokes = character.strokes.size();
  std::vector<std::vector<std::optional<double>>> costs(strokes,
                                                        std::vector<std::optional<double>>(scored.size()));
  std::vector<std::vector<bool>> reversed(strokes, std::vector<bool>(scored.size(), false));
  std::vector<trial_detail::MatchCurve> references;
  for (const PlacedStroke& stroke : character.strokes)
    references.push_back(reference_curve(stroke, placement));
  std::vector<trial_detail::MatchResult> matches(strokes);
  for (std::size_t w = 0; w < scored.size(); ++w) {
    for (std::size_t r = 0; r < strokes; ++r) {
      matches[r] = trial_detail::match_stroke(written[w], references[r], options.leniency);
    }
    for (std::size_t r = 0; r < strokes; ++r) {
      trial_detail::MatchResult match = matches[r];
      if (match.kind == trial_detail::MatchKind::miss) continue;
      // Another stroke that this segment matches forwards more closely: probably the one written.
      double closer = match.mean_distance;
      for (std::size_t other = 0; other < strokes; ++other) {
        if (other != r && matches[other].kind == trial_detail::MatchKind::forwards)
          closer = std::min(closer, matches[other].mean_distance);
      }
      if (closer < match.mean_distance) {
        match = trial_detail::match_stroke(
            written[w], references[r],
            options.leniency * closer_stroke_leniency_factor(closer, match.mean_distance));
        if (match.kind == trial_detail::MatchKind::miss) continue;
      }
      costs[r][w] = match.mean_distance;
      reversed[r][w] = match.kind == trial_detail::MatchKind::backwards;
    }
  }
  const std::vector<std::optional<std::size_t>> assignment = trial_detail::optimal_assignment(costs);

  for (std::size_t r = 0; r < strokes; ++r) {
    StrokeScore& s = score.strokes[r];
    if (!assignment[r]) {
      score.missing_strokes.push_back(r);
      continue;
    }
    const std::size_t w = *assignment[r];
    WrittenSegment& segment = score.segments[scored[w]];
    s.written = true;
    s.segment = scored[w];
    s.backwards = reversed[r][w];
    s.metrics = stroke_writing_metrics(times[w], positions[w], character.strokes[r].elements, options.metrics,
                                       s.backwards);
    segment.matched_stroke = r;
    segment.backwards = s.backwards;
    ++score.strokes_written;
    if (s.backwards) ++score.backwards_strokes;
  }

  std::vector<std::size_t> written_order;  // matched stroke indices in writing order
  for (const WrittenSegment& segment : score.segments) {
    if (segment.matched_stroke) {
      written_order.push_back(*segment.matched_stroke);
    } else if (!segment.ignored) {
      ++score.unmatched_strokes;
    }
  }
  score.order_errors = inversions(written_order);
  score.strokes_in_order = score.strokes_written > 0 && score.order_errors == 0;
  score.completed_in_order = score.strokes_written == strokes && score.order_errors == 0;
  add_timing(score, trace);
  add_spatial_totals(score);
  return score;
}

}  // namespace calligraphy
