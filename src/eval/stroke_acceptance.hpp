#pragma once
// Acceptance of labelled person-like pen paths (sim/person_traces.hpp) by the stroke matcher, per kind:
// the confusion table of docs/stroke-acceptance.md (`calligraphy bench acceptance`) and of its test.
#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/stroke_progress.hpp"
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

/// One empty row per kind of kTraceKinds.
[[nodiscard]] std::vector<KindAcceptance> empty_kind_table();

/// One path of every applicable kind for stroke `stroke`, made from the medians of `source` (the
/// character itself, or another hand's lines in its place) and matched against that stroke of
/// `character`, added to `kinds` (empty_kind_table's rows).
void add_kind_verdicts(std::vector<KindAcceptance>& kinds, const PlacedCharacter& character,
                       const PlacedCharacter& source, std::size_t stroke, std::mt19937_64& random,
                       double start_radius_m, const StrokeAcceptance& acceptance);

/// The markdown confusion table of `kinds`, with the first wrong verdicts.
[[nodiscard]] std::string kind_table_markdown(const std::vector<KindAcceptance>& kinds);

/// The markdown confusion table, with the command that made it.
[[nodiscard]] std::string acceptance_markdown(const AcceptanceMeasurement& measurement,
                                              const std::string& invocation);

}  // namespace calligraphy
