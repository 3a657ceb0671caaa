#pragma once
// The stroke tests of Hanzi Writer's quiz (chanind/hanzi-writer, src/strokeMatches.ts), on curves in the
// 1024-unit data box. Internal.
#include <span>
#include <vector>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::trial_detail {

/// A curve prepared for matching: points in data units (consecutive repeats dropped) and its length.
struct MatchCurve {
  std::vector<Vec2> points;
  double length = 0.0;
};

/// A written stroke prepared for matching: resampled by arc length every kWrittenMatchStep data units, so
/// that the tests see about the density of Hanzi Writer's pointer events whatever the trace's rate.
MatchCurve written_match_curve(std::span<const Vec2> points_data);
/// A reference median prepared for matching (repeats dropped).
MatchCurve reference_match_curve(std::span<const Vec2> median_data);
inline constexpr double kWrittenMatchStep = 10.0;

enum class MatchKind { miss, forwards, backwards };

struct MatchResult {
  MatchKind kind = MatchKind::miss;
  double mean_distance = 0.0;  ///< mean distance of the written points to the reference [data units]
};

/// Hanzi Writer's five tests (mean distance, start and end, direction, shape, length) with `leniency`;
/// when they fail, the same tests on the written curve reversed give `backwards`.
MatchResult match_stroke(const MatchCurve& written, const MatchCurve& reference, double leniency);

}  // namespace calligraphy::trial_detail
