#include "calligraphy/analysis/score.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "analysis/assignment.hpp"
#include "analysis/durations.hpp"
#include "analysis/input_checks.hpp"
#include "analysis/segment_metrics.hpp"
#include "analysis/segmentation.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

std::string character_name(char32_t code_point) {
  char text[16];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(code_point));
  return text;
}

void check_options(const ScoreOptions& options) {
  options.acceptance.validate();
  if (!std::isfinite(options.start_radius_m) || !(options.start_radius_m > 0.0)) {
    throw InvalidArgument("ScoreOptions: start_radius_m " + shortest_decimal(options.start_radius_m) +
                          " m is not finite and > 0");
  }
  if (!std::isfinite(options.min_segment_length_m) || options.min_segment_length_m < 0.0) {
    throw InvalidArgument("ScoreOptions: minimum segment length " +
                          shortest_decimal(options.min_segment_length_m) + " m is not finite and >= 0");
  }
  if (options.max_segments == 0) throw InvalidArgument("ScoreOptions: max_segments is 0");
  trial_detail::require_valid_options(options.metrics);
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
    totals.total_time_s = analysis::whole_nanoseconds(trace[segments.back().end - 1].time_s -
                                                      trace[segments.front().begin].time_s);
  }
  totals.writing_time_s = analysis::whole_nanoseconds(totals.writing_time_s);
  totals.in_air_time_s = analysis::whole_nanoseconds(totals.in_air_time_s);
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

// The counter of `refusal`; none has no counter.
std::size_t RefusalCounts::*counter_of(StrokeRefusal refusal) noexcept {
  switch (refusal) {
    case StrokeRefusal::too_short:
      return &RefusalCounts::too_short;
    case StrokeRefusal::backwards:
      return &RefusalCounts::backwards;
    case StrokeRefusal::wrong_place:
      return &RefusalCounts::wrong_place;
    case StrokeRefusal::wrong_stroke:
      return &RefusalCounts::wrong_stroke;
    case StrokeRefusal::wrong_order:
      return &RefusalCounts::wrong_order;
    case StrokeRefusal::none:
      break;
  }
  return nullptr;
}

}  // namespace

std::size_t RefusalCounts::of(StrokeRefusal refusal) const noexcept {
  const auto counter = counter_of(refusal);
  return counter != nullptr ? this->*counter : 0;
}

void RefusalCounts::add(StrokeRefusal refusal) noexcept {
  if (const auto counter = counter_of(refusal)) ++(this->*counter);
}

std::size_t RefusalCounts::total() const noexcept {
  return too_short + backwards + wrong_place + wrong_stroke + wrong_order;
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
    const StrokeCentreLine& line = character.strokes[r].centre_line;
    if (line.points_m.size() < 2 || line.element_end_arc_m.size() != character.strokes[r].elements.size()) {
      throw InvalidArgument("score_trace: stroke " + std::to_string(r) + " of character " +
                            character_name(character.code_point) +
                            " has no centre line to match against (place it with Scene::lay_out)");
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
  if (score.segments.size() > options.max_segments) {
    throw InvalidArgument("score_trace: the trace has " + std::to_string(score.segments.size()) +
                          " pen-down segments, more than the limit of " +
                          std::to_string(options.max_segments) + " for one scored trace");
  }

  // Samples and kinematics of the scored segments.
  std::vector<std::size_t> scored;  // indices into score.segments
  std::vector<std::vector<double>> times;
  std::vector<std::vector<Vec2>> positions;
  for (std::size_t k = 0; k < score.segments.size(); ++k) {
    WrittenSegment& segment = score.segments[k];
    if (segment.ignored) {
      ++score.ignored_segments;
      continue;
    }
    std::vector<double> t;
    std::vector<Vec2> p;
    for (std::size_t i = segment.begin; i < segment.end; ++i) {
      t.push_back(trace[i].time_s);
      p.push_back(trace[i].position_m);
      if (!placement.to_data(trace[i].position_m).allFinite()) {
        throw InvalidArgument("score_trace: sample " + std::to_string(i) +
                              " is too far away to convert to data units");
      }
    }
    segment.kinematics = stroke_kinematics(t, p, options.metrics.kinematics);
    scored.push_back(k);
    times.push_back(std::move(t));
    positions.push_back(std::move(p));
  }

  // The renderer's verdict on each segment in sequence: the stroke expected advances with each acceptance,
  // and after assist_after_misses misses of it, as the renderer demonstrates and credits it
  // (ActiveStroke::lift; Hanzi Writer's markStrokeCorrectAfterMisses). A refused pen-down is a miss as the
  // renderer counts it (StrokeAcceptance::counts_as_miss): any that moved far enough in the box (with
  // `miss_min_path_m` 0, as records before version 8 ran, a lift in WS only); one the trace ends in before a
  // lift is refused but no miss (the renderer judges an attempt at its lift).
  const std::size_t strokes = character.strokes.size();
  const double assist_after = options.acceptance.assist_after_misses;
  std::size_t expected = 0;
  double misses = 0.0;
  for (std::size_t w = 0; w < scored.size() && expected < strokes; ++w) {
    const StrokeMatch verdict =
        match_stroke(character, expected, positions[w], options.start_radius_m, options.acceptance);
    WrittenSegment& segment = score.segments[scored[w]];
    segment.verdict = verdict;
    segment.due_stroke = expected;
    if (verdict.accepted) {
      ++expected;
      ++score.strokes_accepted;
      misses = 0.0;
      continue;
    }
    score.refusals.add(verdict.refusal);
    const bool lifted = segment.end < trace.size();
    const RefusedPenDown pen_down{
        .entered_ws = verdict.entered,
        .in_character_box = std::any_of(positions[w].begin(), positions[w].end(),
                                        [&](const Vec2& p) { return character.bounding_box.contains(p); }),
        .path_m = segment.kinematics->path_length_m,
        .samples = positions[w].size()};
    if (!lifted || !options.acceptance.counts_as_miss(pen_down)) continue;
    misses += 1.0;
    if (assist_after > 0.0 && misses >= assist_after) {
      segment.assists_due = true;
      score.strokes[expected].assisted = true;
      ++score.strokes_assisted;
      ++expected;
      misses = 0.0;
    }
  }

  // Every (reference stroke, scored segment) pair the stroke matcher writes, forwards or else backwards, at
  // the cost of the attempt's mean deviation; then the one-to-one assignment.
  std::vector<std::vector<std::optional<double>>> costs(strokes,
                                                        std::vector<std::optional<double>>(scored.size()));
  std::vector<std::vector<bool>> reversed(strokes, std::vector<bool>(scored.size(), false));
  if (options.progress) options.progress(0, scored.size());
  for (std::size_t w = 0; w < scored.size(); ++w) {
    if (options.progress && w > 0) options.progress(w, scored.size());
    const std::vector<Vec2> backwards_path(positions[w].rbegin(), positions[w].rend());
    for (std::size_t r = 0; r < strokes; ++r) {
      const PlacedStroke& stroke = character.strokes[r];
      const StrokeAttempt forwards =
          attempt_stroke(stroke, positions[w], options.start_radius_m, options.acceptance);
      if (forwards.written) {
        costs[r][w] = forwards.mean_deviation_m;
        continue;
      }
      const StrokeAttempt backwards =
          attempt_stroke(stroke, backwards_path, options.start_radius_m, options.acceptance);
      if (backwards.written) {
        costs[r][w] = backwards.mean_deviation_m;
        reversed[r][w] = true;
      }
    }
  }
  if (options.progress) options.progress(scored.size(), scored.size());
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
    // The segment's kinematics, computed above from the same samples and options.
    s.metrics = trial_detail::stroke_writing_metrics(
        *segment.kinematics, positions[w], character.strokes[r].elements, options.metrics, s.backwards);
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
