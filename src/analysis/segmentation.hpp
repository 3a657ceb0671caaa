#pragma once
// Cutting a pen trace into pen-down segments. Internal.
#include <span>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy::trial_detail {

/// Every maximal run of pen-down samples, in order, with `ignored` set for runs with fewer than
/// `min_samples` samples, a path shorter than `min_length_m` (or of
/// zero length) or no time span. Other fields left empty.
std::vector<WrittenSegment> pen_down_segments(std::span<const PenSample> trace, std::size_t min_samples,
                                              double min_length_m);

/// The character of `scene` each pen-down run of `trace` belongs to, as an index per sample (pen-up samples:
/// SIZE_MAX): the character whose box (`PlacedCharacter::bounding_box`) holds most of the run's samples, or,
/// when no box holds any, the one whose box is nearest the run's first sample. `scene` has a character.
std::vector<std::size_t> character_of_samples(const Scene& scene, std::span<const PenSample> trace);

}  // namespace calligraphy::trial_detail
