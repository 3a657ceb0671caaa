#include "calligraphy/model/stroke_progress.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

namespace {

constexpr ParameterRange kLength{.low = 0.0, .high = 0.1, .low_open = true};

// In the order a trial record has always written them.
constexpr std::array kAcceptanceFields{
    ParameterField<StrokeAcceptance>{"corridor_m", "m", kLength,
                                     "farthest the pen may be from the centre line and still make progress",
                                     &StrokeAcceptance::corridor_m},
    ParameterField<StrokeAcceptance>{"mean_deviation_m", "m", kLength,
                                     "largest mean distance of the pen from the centre line",
                                     &StrokeAcceptance::mean_deviation_m},
    ParameterField<StrokeAcceptance>{"shortfall_m", "m", kLength,
                                     "how much shorter than the stroke the way along it may be",
                                     &StrokeAcceptance::shortfall_m},
    ParameterField<StrokeAcceptance>{
        "shortfall_fraction", "",
        ParameterRange{.low = 0.0, .high = 1.0, .low_open = true, .high_open = true},
        "the shortfall as a fraction of the stroke's length, the smaller applying",
        &StrokeAcceptance::shortfall_fraction},
    ParameterField<StrokeAcceptance>{"displacement_m", "m", kLength,
                                     "how far a copy of the stroke may be displaced along it",
                                     &StrokeAcceptance::displacement_m},
    ParameterField<StrokeAcceptance>{"follow_through_m", "m", kLength,
                                     "radius of the end neighbourhood a pen past the end may move in",
                                     &StrokeAcceptance::follow_through_m},
    ParameterField<StrokeAcceptance>{"max_gain_ratio", "", ParameterRange{.low = 1.0, .high = 100.0},
                                     "most arc credited per length of pen motion",
                                     &StrokeAcceptance::max_gain_ratio},
    ParameterField<StrokeAcceptance>{"lookahead_m", "m", kLength,
                                     "how far along the centre line the foot point is looked for",
                                     &StrokeAcceptance::lookahead_m},
    // Added with version 4 of a trial record; older records run with use_fixed_tolerances().
    ParameterField<StrokeAcceptance>{"shortfall_per_length", "", ParameterRange{.low = 0.0, .high = 1.0},
                                     "growth of the shortfall allowed with the stroke's length",
                                     &StrokeAcceptance::shortfall_per_length},
    ParameterField<StrokeAcceptance>{"shortfall_cap_m", "m", kLength, "most shortfall allowed on any stroke",
                                     &StrokeAcceptance::shortfall_cap_m},
    ParameterField<StrokeAcceptance>{"deviation_per_length", "", ParameterRange{.low = 0.0, .high = 1.0},
                                     "growth of the mean deviation allowed with the stroke's length",
                                     &StrokeAcceptance::deviation_per_length},
    ParameterField<StrokeAcceptance>{"mean_deviation_cap_m", "m", kLength,
                                     "most mean deviation allowed on any stroke",
                                     &StrokeAcceptance::mean_deviation_cap_m},
    ParameterField<StrokeAcceptance>{"reference_character_size_m", "m",
                                     ParameterRange{.low = 0.0, .high = 1.0},
                                     "the character size the lengths are for, 0 for absolute lengths",
                                     &StrokeAcceptance::reference_character_size_m},
    ParameterField<StrokeAcceptance>{
        "hint_after_misses", "", ParameterRange{.low = 0.0, .high = 1000.0},
        "refused attempts at a stroke after which it is shown as a hint, 0 never",
        &StrokeAcceptance::hint_after_misses, true},
    ParameterField<StrokeAcceptance>{
        "assist_after_misses", "", ParameterRange{.low = 0.0, .high = 1000.0},
        "refused attempts at a stroke after which it is demonstrated and credited assisted, 0 never",
        &StrokeAcceptance::assist_after_misses, true},
    // Added with version 5 of a trial record; older records run with use_version_4_end_gaps().
    ParameterField<StrokeAcceptance>{"end_gap_m", "m", ParameterRange{.low = 0.0, .high = 0.1},
                                     "least either end may be left unwritten by on a stroke long enough, 0 "
                                     "for none",
                                     &StrokeAcceptance::end_gap_m},
    ParameterField<StrokeAcceptance>{
        "end_gap_fraction", "", ParameterRange{.low = 0.0, .high = 1.0, .high_open = true},
        "the end gap's floor as a fraction of the stroke's length, the smaller applying",
        &StrokeAcceptance::end_gap_fraction},
    // Added with version 7 of a trial record; older records run with use_version_6_coverage().
    ParameterField<StrokeAcceptance>{
        "centred_coverage_fraction", "", ParameterRange{.low = 0.0, .high = 1.0, .high_open = true},
        "least share of a dot or short tick a path centred on it covers to write it, 0 for no such rule",
        &StrokeAcceptance::centred_coverage_fraction},
    ParameterField<StrokeAcceptance>{
        "centred_balance_fraction", "", ParameterRange{.low = 0.0, .high = 1.0},
        "most the gaps a centred path leaves at the two ends may differ by, as a fraction of the length",
        &StrokeAcceptance::centred_balance_fraction},
    ParameterField<StrokeAcceptance>{"centred_min_length_m", "m", ParameterRange{.low = 0.0, .high = 0.1},
                                     "shortest stroke the centred rule applies to",
                                     &StrokeAcceptance::centred_min_length_m},
    ParameterField<StrokeAcceptance>{"centred_max_length_m", "m", ParameterRange{.low = 0.0, .high = 0.1},
                                     "longest stroke the centred rule applies to",
                                     &StrokeAcceptance::centred_max_length_m},
    // Added with version 8 of a trial record; older records run with use_version_7_misses().
    ParameterField<StrokeAcceptance>{"miss_min_path_m", "m", ParameterRange{.low = 0.0, .high = 0.1},
                                     "least path of a refused pen-down for it to count as a miss wherever it "
                                     "was, 0 for a lift in WS only",
                                     &StrokeAcceptance::miss_min_path_m},
};

}  // namespace

std::span<const ParameterField<StrokeAcceptance>> ParameterTable<StrokeAcceptance>::fields() noexcept {
  return kAcceptanceFields;
}

void StrokeAcceptance::validate() const {
  check_parameters(*this);  // the miss counts whole numbers too (ParameterField::whole_number)
}

double StrokeAcceptance::allowed_shortfall_m(double length_m) const noexcept {
  return std::min(
      {shortfall_m + shortfall_per_length * length_m, shortfall_cap_m, shortfall_fraction * length_m});
}

double StrokeAcceptance::allowed_end_gap_m(double length_m) const noexcept {
  return std::max(
      {allowed_shortfall_m(length_m), displacement_m, std::min(end_gap_m, end_gap_fraction * length_m)});
}

bool StrokeAcceptance::centred_cover(double length_m, double way_along_m, double start_gap_m,
                                     double finish_gap_m) const noexcept {
  if (!(centred_coverage_fraction > 0.0) || length_m < centred_min_length_m ||
      length_m > centred_max_length_m)
    return false;
  const double end_gap_limit = allowed_end_gap_m(length_m);
  return way_along_m >= centred_coverage_fraction * length_m && start_gap_m <= end_gap_limit &&
         finish_gap_m <= end_gap_limit &&
         std::abs(start_gap_m - finish_gap_m) <= centred_balance_fraction * length_m;
}

bool StrokeAcceptance::counts_as_miss(const RefusedPenDown& pen_down) const noexcept {
  if (!(miss_min_path_m > 0.0)) return pen_down.entered_ws;  // before version 8: every lift in WS, no other
  return (pen_down.entered_ws || pen_down.in_character_box) && pen_down.samples >= kMinMissSamples &&
         pen_down.path_m >= miss_min_path_m;
}

double StrokeAcceptance::allowed_mean_deviation_m(double length_m) const noexcept {
  return std::min(mean_deviation_m + deviation_per_length * length_m, mean_deviation_cap_m);
}

void StrokeAcceptance::use_fixed_tolerances() noexcept {
  shortfall_per_length = 0.0;
  shortfall_cap_m = kLength.high;
  deviation_per_length = 0.0;
  mean_deviation_cap_m = kLength.high;
  reference_character_size_m = 0.0;
  assist_after_misses = 0.0;
  use_version_4_end_gaps();
  use_version_6_coverage();
  use_version_7_misses();
}

StrokeAcceptance StrokeAcceptance::for_character_size(double character_size_m) const noexcept {
  if (!(reference_character_size_m > 0.0) || !(character_size_m > 0.0)) return *this;
  const double k = character_size_m / reference_character_size_m;
  StrokeAcceptance out = *this;
  for (double StrokeAcceptance::*length :
       {&StrokeAcceptance::corridor_m, &StrokeAcceptance::mean_deviation_m, &StrokeAcceptance::shortfall_m,
        &StrokeAcceptance::displacement_m, &StrokeAcceptance::lookahead_m,
        &StrokeAcceptance::follow_through_m, &StrokeAcceptance::shortfall_cap_m,
        &StrokeAcceptance::mean_deviation_cap_m, &StrokeAcceptance::end_gap_m,
        &StrokeAcceptance::centred_min_length_m, &StrokeAcceptance::centred_max_length_m}) {
    out.*length *= k;
  }
  return out;
}

const char* to_string(StrokeRefusal refusal) noexcept {
  switch (refusal) {
    case StrokeRefusal::none:
      return "none";
    case StrokeRefusal::too_short:
      return "too_short";
    case StrokeRefusal::backwards:
      return "backwards";
    case StrokeRefusal::wrong_place:
      return "wrong_place";
    case StrokeRefusal::wrong_stroke:
      return "wrong_stroke";
    case StrokeRefusal::wrong_order:
      return "wrong_order";
  }
  return "?";
}

StrokeProgressTracker::Foot StrokeProgressTracker::foot_near(const Vec2& tip_m, double from_arc_m,
                                                             double to_arc_m) const noexcept {
  const StrokeCentreLine& line = stroke_->centre_line;
  Foot best{from_arc_m, std::numeric_limits<double>::infinity(), Vec2::UnitX()};
  // Only the segments in the window: the first that ends at or after from_arc_m, by bisection (the arcs
  // increase), up to the first that starts after to_arc_m.
  const auto first_end = std::lower_bound(line.arc_m.begin() + 1, line.arc_m.end(), from_arc_m);
  for (auto k = static_cast<std::size_t>(first_end - line.arc_m.begin()); k < line.points_m.size(); ++k) {
    const double arc_a = line.arc_m[k - 1];
    const double arc_b = line.arc_m[k];
    if (arc_a > to_arc_m) break;
    const Vec2& a = line.points_m[k - 1];
    const Vec2& b = line.points_m[k];
    const double segment = arc_b - arc_a;
    if (!(segment > 0.0)) continue;
    const double t_from = std::max(0.0, (from_arc_m - arc_a) / segment);
    const double t_to = std::min(1.0, (to_arc_m - arc_a) / segment);
    const double t = std::clamp(segment_parameter(a, b, tip_m), t_from, t_to);
    const double distance = (a + t * (b - a) - tip_m).norm();
    if (distance < best.distance_m) best = Foot{arc_a + t * segment, distance, (b - a) / segment};
  }
  if (!std::isfinite(best.distance_m)) {  // a zero-length line: its one point
    best.distance_m = (line.points_m.front() - tip_m).norm();
    best.arc_m = 0.0;
  }
  return best;
}

void StrokeProgressTracker::begin(const PlacedStroke& stroke, const Vec2& tip_m,
                                  const StrokeAcceptance& acceptance) noexcept {
  stroke_ = &stroke;
  acceptance_ = acceptance.for_character_size(stroke.character_size_m);
  const StrokeCentreLine& line = stroke.centre_line;
  const Foot foot = foot_near(tip_m, 0.0, line.start_arc_m + acceptance_.lookahead_m);
  entry_arc_m_ = foot.arc_m;
  progress_m_ = foot.arc_m;
  last_tip_m_ = tip_m;
  travel_m_ = 0.0;
  distance_integral_m2_ = 0.0;
  entry_distance_m_ = std::min(foot.distance_m, 2.0 * acceptance_.corridor_m);
  backward_m_ = 0.0;
  past_end_m_ = 0.0;
  before_start_m_ = std::max(0.0, (stroke.start() - tip_m).dot(stroke.elements.front().unit_tangent(0.0)));
  outside_corridor_ = foot.distance_m > acceptance_.corridor_m;
  attempt_ = true;
  passed_end_ = false;
  lost_ = false;
}

bool StrokeProgressTracker::update(const Vec2& tip_m) noexcept {
  if (!attempt_) return false;
  if (passed_end_) {
    // In the end neighbourhood the pen may go anywhere until it lifts; leaving it ends the attempt: written
    // if the pen is back on the stroke, lost if it went off it.
    if ((tip_m - stroke_->end()).norm() <= acceptance_.follow_through_m) return false;
    attempt_ = false;
    const Foot foot =
        foot_near(tip_m, progress_m_ - acceptance_.follow_through_m - acceptance_.lookahead_m, progress_m_);
    lost_ = foot.distance_m > acceptance_.mean_deviation_m;
    return !lost_;
  }
  const Vec2 step = tip_m - last_tip_m_;
  const double step_m = step.norm();
  last_tip_m_ = tip_m;
  const Foot foot =
      foot_near(tip_m, progress_m_ - acceptance_.lookahead_m, progress_m_ + acceptance_.lookahead_m);
  travel_m_ += step_m;
  distance_integral_m2_ += step_m * std::min(foot.distance_m, 2.0 * acceptance_.corridor_m);
  outside_corridor_ = foot.distance_m > acceptance_.corridor_m;
  if (!outside_corridor_) {
    const double along = step.dot(foot.tangent);
    if (along > 0.0 && foot.arc_m > progress_m_) {
      progress_m_ = std::min(foot.arc_m, progress_m_ + acceptance_.max_gain_ratio * step_m);
    } else if (along < 0.0) {
      backward_m_ -= along;
    }
    // A pen that carried on past a corner (outside it) has crossed the corner's feature plane (eq. 6)
    // while its foot on the rounded median may still lie just short of the corner: the corner is gone round.
    const std::size_t element = element_index();
    const std::vector<double>& corners = stroke_->centre_line.element_end_arc_m;
    if (element + 1 < corners.size() && progress_m_ >= corners[element] - acceptance_.lookahead_m &&
        feature_plane_passed(stroke_->elements[element], tip_m)) {
      progress_m_ = std::max(progress_m_, corners[element]);
    }
  }
  if (progress_m_ >= stroke_->centre_line.element_end_arc_m.back()) {
    past_end_m_ =
        std::max(past_end_m_, (tip_m - stroke_->end()).dot(stroke_->elements.back().unit_tangent(1.0)));
    passed_end_ = written();
  }
  return false;
}

bool StrokeProgressTracker::lift() noexcept {
  if (!attempt_) return false;
  attempt_ = false;
  return passed_end_ || written();
}

double StrokeProgressTracker::stroke_length_m() const noexcept {
  if (stroke_ == nullptr) return 0.0;
  const StrokeCentreLine& line = stroke_->centre_line;
  return std::max(0.0, line.element_end_arc_m.back() - line.start_arc_m);
}

double StrokeProgressTracker::way_along_m() const noexcept {
  if (stroke_ == nullptr) return 0.0;
  // The arc gained between the first and last feature points (not along a brush hook of the median
  // before or after them), and the run beyond each, measured along the stroke's direction there.
  const StrokeCentreLine& line = stroke_->centre_line;
  const double from = std::max(entry_arc_m_, line.start_arc_m);
  const double to = std::min(progress_m_, line.element_end_arc_m.back());
  const double d = acceptance_.displacement_m;
  return std::max(0.0, to - from) + std::min(before_start_m_, d) + std::min(past_end_m_, d);
}

double StrokeProgressTracker::mean_deviation_m() const noexcept {
  return travel_m_ > 0.0 ? distance_integral_m2_ / travel_m_ : entry_distance_m_;
}

bool StrokeProgressTracker::written() const noexcept {
  const StrokeCentreLine& line = stroke_->centre_line;
  const double length = stroke_length_m();
  const double shortfall = acceptance_.allowed_shortfall_m(length);
  const double end_gap_limit = acceptance_.allowed_end_gap_m(length);
  const double start_gap = entry_arc_m_ - line.start_arc_m;
  const double end_gap = line.element_end_arc_m.back() - progress_m_;
  if (mean_deviation_m() > acceptance_.allowed_mean_deviation_m(length)) return false;
  const double way = way_along_m();
  return (way >= length - shortfall && start_gap <= end_gap_limit && end_gap <= end_gap_limit) ||
         acceptance_.centred_cover(length, way, start_gap, end_gap);
}

std::size_t StrokeProgressTracker::element_index() const noexcept {
  if (stroke_ == nullptr) return 0;
  const std::vector<double>& ends = stroke_->centre_line.element_end_arc_m;
  for (std::size_t i = 0; i + 1 < ends.size(); ++i) {
    if (progress_m_ < ends[i]) return i;
  }
  return ends.empty() ? 0 : ends.size() - 1;
}

StrokeRefusal StrokeProgressTracker::refusal() const noexcept {
  if (stroke_ == nullptr) return StrokeRefusal::wrong_place;
  if (lost_) return StrokeRefusal::wrong_stroke;
  if (passed_end_ || written()) return StrokeRefusal::none;
  if (mean_deviation_m() > acceptance_.allowed_mean_deviation_m(stroke_length_m()))
    return StrokeRefusal::wrong_place;
  const double forward = progress_m_ - entry_arc_m_;
  if (backward_m_ > forward && backward_m_ > 0.25 * acceptance_.corridor_m) return StrokeRefusal::backwards;
  if (outside_corridor_) return StrokeRefusal::wrong_stroke;
  return StrokeRefusal::too_short;
}

}  // namespace calligraphy
