#pragma once
/// \file polyline.hpp
/// Small polyline and angle helpers shared by fitting, metrics and drawing (lengths in the polyline's units,
/// angles in radians unless named _deg).
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// Direction of v in degrees, (-180, 180], y up.
double direction_deg(const Vec2& v);
/// a wrapped into (-180, 180].
double wrap_deg(double a);
/// Signed turn from direction a to direction b, degrees, counter-clockwise positive.
double turn_deg(const Vec2& a, const Vec2& b);

std::vector<Vec2> without_repeats(std::span<const Vec2> pts);
double polyline_length(std::span<const Vec2> pts);
/// Points every `step` along the polyline, both ends included: about length / step + 2 points, so the
/// caller bounds the count by its choice of step. Empty when `step` is not positive.
std::vector<Vec2> resample(std::span<const Vec2> pts, double step);
/// Max distance of the points from the chord front-back.
double max_chord_deviation(std::span<const Vec2> pts);
/// Index of the interior point farthest from the chord (1 when there is none farther).
std::size_t farthest_from_chord(std::span<const Vec2> pts);
/// `segments` + 1 points along the element at equal parameter steps.
std::vector<Vec2> sample_element(const StrokeElement& element, int segments);
/// Distance from p to the polyline.
double distance_to_polyline(const Vec2& p, std::span<const Vec2> pts);
/// Max over `points` of distance_to_polyline(point, pts), exactly, with early exits. 0 when `points` is
/// empty. Returns as soon as the max exceeds `stop_above` (then some distance above it, not the max).
double max_distance_to_polyline(std::span<const Vec2> points, std::span<const Vec2> pts,
                                double stop_above = std::numeric_limits<double>::infinity());
/// max_distance_to_polyline, or nullopt when it would take more than `max_evaluations` point-segment
/// distances (at most points * segments; far more where the nearest segments of many points tie within
/// rounding on a polyline that overlaps itself).
std::optional<double> max_distance_to_polyline_within(std::span<const Vec2> points, std::span<const Vec2> pts,
                                                      std::size_t max_evaluations);

}  // namespace calligraphy
