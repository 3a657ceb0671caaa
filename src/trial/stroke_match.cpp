#include "trial/stroke_match.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "calligraphy/collision/nearest_point.hpp"
#include "calligraphy/trial/metrics.hpp"

namespace calligraphy::trial_detail {
namespace {

// Thresholds of Hanzi Writer's strokeMatches.ts, in its 1024-unit data box.
constexpr double kMeanDistanceThreshold = 350.0;
// Hanzi Writer halves the mean-distance threshold when the outline is shown or the stroke is not the first.
// A trace scored here was written over a displayed model, so the halved threshold applies to every stroke.
constexpr double kOutlineShownFactor = 0.5;
constexpr double kEndpointThreshold = 250.0;
constexpr double kCosineThreshold = 0.0;
constexpr double kFrechetThreshold = 0.4;  // on curves normalised as below
constexpr double kMinLengthRatio = 0.35;
constexpr double kLengthOffset = 25.0;     // added to both lengths, so that short strokes are not failed
constexpr std::size_t kShapePoints = 30;   // points of the resampled curves of the shape test
constexpr double kShapeMaxSegment = 0.05;  // normalised curves are subdivided to segments <= this
constexpr std::array<double, 5> kShapeRotations{std::numbers::pi / 16, std::numbers::pi / 32, 0.0,
                                                -std::numbers::pi / 32, -std::numbers::pi / 16};

double polyline_length(const std::vector<Vec2>& points) {
  double length = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

std::vector<Vec2> without_repeats(std::span<const Vec2> points) {
  std::vector<Vec2> out;
  for (const Vec2& p : points) {
    if (out.empty() || p != out.back()) out.push_back(p);
  }
  return out;
}

double distance_to_polyline(const Vec2& p, const std::vector<Vec2>& polyline) {
  if (polyline.size() == 1) return (p - polyline.front()).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < polyline.size(); ++i) {
    best = std::min(best, nearest_point_on_segment(polyline[i - 1], polyline[i], p).distance);
  }
  return best;
}

// Mean distance of the written points to the reference polyline. (Hanzi Writer measures to the nearest
// median vertex; the polyline is the stroke itself, so its segments are used here.)
double mean_distance(const MatchCurve& written, const MatchCurve& reference) {
  double sum = 0.0;
  for (const Vec2& p : written.points) sum += distance_to_polyline(p, reference.points);
  return sum / static_cast<double>(written.points.size());
}

bool endpoints_match(const std::vector<Vec2>& written, const MatchCurve& reference, double leniency) {
  return (written.front() - reference.points.front()).norm() <= kEndpointThreshold * leniency &&
         (written.back() - reference.points.back()).norm() <= kEndpointThreshold * leniency;
}

// Mean over the written segments of the best cosine similarity to any reference segment.
bool direction_matches(const std::vector<Vec2>& written, const MatchCurve& reference) {
  if (written.size() < 2) return false;
  double sum = 0.0;
  for (std::size_t i = 1; i < written.size(); ++i) {
    const Vec2 edge = (written[i] - written[i - 1]).normalized();
    double best = -1.0;
    for (std::size_t j = 1; j < reference.points.size(); ++j) {
      best = std::max(best, edge.dot((reference.points[j] - reference.points[j - 1]).normalized()));
    }
    sum += best;
  }
  return sum / static_cast<double>(written.size() - 1) > kCosineThreshold;
}

// Hanzi Writer's normalisation (Procrustes-like): 30 points by arc length, centred on their mean, scaled
// so that the RMS distance of the two end points from the mean is 1, then subdivided. Empty when the
// scale vanishes.
std::vector<Vec2> normalised_curve(const std::vector<Vec2>& points) {
  std::vector<Vec2> curve = resample_by_arc_length(points, kShapePoints);
  Vec2 mean = Vec2::Zero();
  for (const Vec2& p : curve) mean += p;
  mean /= static_cast<double>(curve.size());
  for (Vec2& p : curve) p -= mean;
  const double scale = std::sqrt(0.5 * (curve.front().squaredNorm() + curve.back().squaredNorm()));
  if (!(scale > 1e-12)) return {};
  std::vector<Vec2> out{curve.front() / scale};
  for (std::size_t i = 1; i < curve.size(); ++i) {
    const Vec2 a = curve[i - 1] / scale;
    const Vec2 b = curve[i] / scale;
    const auto pieces = std::max(1.0, std::ceil((b - a).norm() / kShapeMaxSegment));
    for (double k = 1.0; k <= pieces; k += 1.0) out.push_back(a + (k / pieces) * (b - a));
  }
  return out;
}

bool shape_matches(const std::vector<Vec2>& written, const MatchCurve& reference, double leniency) {
  const std::vector<Vec2> a = normalised_curve(written);
  const std::vector<Vec2> b = normalised_curve(reference.points);
  if (a.empty() || b.empty()) return false;
  std::vector<Vec2> rotated(b.size());
  double best = std::numeric_limits<double>::infinity();
  for (const double theta : kShapeRotations) {
    const Eigen::Rotation2Dd rotation(theta);
    for (std::size_t i = 0; i < b.size(); ++i) rotated[i] = rotation * b[i];
    best = std::min(best, discrete_frechet_distance(a, rotated));
  }
  return best <= kFrechetThreshold * leniency;
}

bool length_matches(double written_length, const MatchCurve& reference, double leniency) {
  return leniency * (written_length + kLengthOffset) / (reference.length + kLengthOffset) >= kMinLengthRatio;
}

bool passes(const std::vector<Vec2>& written, double written_length, const MatchCurve& reference,
            double leniency) {
  return endpoints_match(written, reference, leniency) && direction_matches(written, reference) &&
         length_matches(written_length, reference, leniency) && shape_matches(written, reference, leniency);
}

}  // namespace

MatchCurve written_match_curve(std::span<const Vec2> points_data) {
  MatchCurve curve;
  curve.points = without_repeats(points_data);
  curve.length = polyline_length(curve.points);
  if (curve.points.size() >= 2) {
    const double intervals = std::min(std::ceil(curve.length / kWrittenMatchStep), 1000.0);
    curve.points =
        resample_by_arc_length(curve.points, static_cast<std::size_t>(std::max(intervals, 1.0)) + 1);
  }
  return curve;
}

MatchCurve reference_match_curve(std::span<const Vec2> median_data) {
  MatchCurve curve;
  curve.points = without_repeats(median_data);
  curve.length = polyline_length(curve.points);
  return curve;
}

MatchResult match_stroke(const MatchCurve& written, const MatchCurve& reference, double leniency) {
  MatchResult result;
  if (written.points.size() < 2 || reference.points.size() < 2) return result;
  result.mean_distance = mean_distance(written, reference);
  // The mean distance is the same both ways, and cheap: it rules most pairs out before the other tests.
  if (result.mean_distance > kMeanDistanceThreshold * kOutlineShownFactor * leniency) return result;
  if (passes(written.points, written.length, reference, leniency)) {
    result.kind = MatchKind::forwards;
    return result;
  }
  std::vector<Vec2> reversed(written.points.rbegin(), written.points.rend());
  if (passes(reversed, written.length, reference, leniency)) result.kind = MatchKind::backwards;
  return result;
}

}  // namespace calligraphy::trial_detail
