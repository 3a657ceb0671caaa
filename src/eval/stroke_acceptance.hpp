#pragma once
// Acceptance of labelled person-like pen paths (sim/person_traces.hpp) by the stroke matcher, per kind:
// the confusion table of docs/stroke-acceptance.md (`calligraphy bench acceptance`) and of its test.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/person_traces.hpp"

namespace calligraphy {

/// Verdicts on the paths of one kind: how many were accepted, and the refusals by reason.
struct KindAcceptance {
  TraceKind kind = TraceKind::median;
  std::size_t paths = 0;
  std::size_t accepted = 0;
  std::array<std::size_t, 6> by_refusal{};  ///< indexed by StrokeRefusal
  /// Up to five examples of the minority verdict (refused positives, accepted negatives): "字 stroke 3".
  std::vector<std::string> examples;
};

struct AcceptanceMeasurement {
  std::vector<char32_t> characters;  ///< the characters measured, in the order drawn
  std::uint64_t seed = 0;
  std::size_t strokes = 0;
  std::vector<KindAcceptance> kinds;  ///< in kTraceKinds order
};

/// `count` characters drawn at random with `seed` from `library`, leaving out those in `excluded`.
[[nodiscard]] std::vector<char32_t> random_characters(const CharacterLibrary& library, std::size_t count,
                                                      std::uint64_t seed,
                                                      const std::vector<char32_t>& excluded);

/// One path of every applicable kind for every stroke of every character (60 mm boxes), matched against
/// its stroke with the renderer's start radius and `acceptance`. Deterministic for a seed.
[[nodiscard]] AcceptanceMeasurement measure_acceptance(const CharacterLibrary& library,
                                                       const std::vector<char32_t>& characters,
                                                       std::uint64_t seed,
                                                       const StrokeAcceptance& acceptance = {});

/// The markdown confusion table, with the command that made it.
[[nodiscard]] std::string acceptance_markdown(const AcceptanceMeasurement& measurement,
                                              const std::string& invocation);

}  // namespace calligraphy
