#pragma once
// Another hand's strokes: KanjiVG's stroke centre lines (Ulrich Apel, CC BY-SA 3.0; used only in tests and
// benchmarks, never shipped) of the characters that hanzi-writer-data also has with as many strokes,
// aligned to the data's medians by one uniform scale and shift per character, and written as a
// position-only pen at a person's pace (sim/person_traces.hpp `pointer_trace`) along the KanjiVG line,
// never along the median. Measures how many strokes and characters a person's hand completes, with and
// without the trial's assisted credit, and how the negative kinds made from those lines fare
// (docs/stroke-acceptance.md, `calligraphy bench acceptance --kanjivg DIR`).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "eval/stroke_acceptance.hpp"

namespace calligraphy {

/// KanjiVG's file of a character in `folder`: kanji/XXXXX.svg, five lower-case hex digits.
[[nodiscard]] std::filesystem::path kanjivg_file(const std::filesystem::path& folder, char32_t code_point);

/// The stroke centre lines of a KanjiVG file in stroke order (its `<path d="...">` elements in document
/// order), in KanjiVG's units (109 box, y down), curves flattened within 0.05 units. Throws DataError
/// naming the file for a file that cannot be read or a path that cannot be parsed.
[[nodiscard]] std::vector<std::vector<Vec2>> read_kanjivg_strokes(const std::filesystem::path& file);

/// `strokes` (KanjiVG units, y down) mapped onto the medians of `character` (metres on the paper, y up) by
/// one uniform scale and shift: the least-squares fit over all stroke points, each stroke and its median
/// resampled to the same number of points by arc length. `strokes` must have as many strokes as
/// `character`, each with a median. Returns the lines in metres.
[[nodiscard]] std::vector<std::vector<Vec2>> align_to_medians(const std::vector<std::vector<Vec2>>& strokes,
                                                              const PlacedCharacter& character);

/// The same form's default tolerance: a KanjiVG line farther than this from its median (discrete Frechet
/// distance, 60 mm box) is another form of the stroke, as far as the smallest parallel shift a matcher must
/// refuse (4 mm).
inline constexpr double kSameFormFrechet_m = 0.004;

/// True when every aligned line (align_to_medians) of `lines` lies nearer its own stroke's median, in the
/// same direction, than any other stroke's (the same order: KanjiVG follows the Japanese order, which
/// differs from the Chinese for some characters), and within a discrete Frechet distance (Eiter & Mannila
/// 1994) of `form_tolerance_m` of it in a 60 mm box (the same form: farther is another glyph's stroke).
[[nodiscard]] bool same_order_and_form(const std::vector<std::vector<Vec2>>& lines,
                                       const PlacedCharacter& character,
                                       double form_tolerance_m = kSameFormFrechet_m);

/// Which half of the intersection: the rule's tolerances are tuned on one and measured on the other, so
/// that a measured rate is not one the tuning has fitted.
enum class KanjivgHalf : std::uint8_t { tuning, held_out, whole };

/// "tuning", "held-out", "whole".
[[nodiscard]] const char* to_string(KanjivgHalf half) noexcept;

/// The half a character belongs to: a fixed hash of its code point (SplitMix64, Steele, Lea & Flood 2014),
/// even to `tuning`, odd to `held_out`; the same whatever is drawn, seeded or measured.
[[nodiscard]] KanjivgHalf kanjivg_half_of(char32_t code_point) noexcept;

/// The characters drawn from the intersection, and how many passed each filter (over the whole pool
/// looked at: the draw stops once `count` characters are chosen, so the counts are of the pool drawn).
struct SharedCharacters {
  std::vector<char32_t> chosen;
  std::size_t with_file = 0;   ///< in the library (not excluded), in the half, with a KanjiVG file
  std::size_t looked_at = 0;   ///< of those, looked at before `count` were chosen
  std::size_t same_count = 0;  ///< of those, with as many strokes
  std::size_t same_order = 0;  ///< of those, in the same order
  std::size_t same_form = 0;   ///< of those, every line within the form tolerance: `chosen`
};

/// Up to `count` characters drawn at random with `seed` from `half` of the whole intersection: those
/// `library` has (but not `excluded`) whose KanjiVG file in `folder` exists, has as many strokes, and is
/// in the same order and form (same_order_and_form with `form_tolerance_m`).
[[nodiscard]] SharedCharacters draw_shared_characters(const CharacterLibrary& library,
                                                      const std::filesystem::path& folder, std::size_t count,
                                                      std::uint64_t seed,
                                                      const std::vector<char32_t>& excluded,
                                                      double form_tolerance_m = kSameFormFrechet_m,
                                                      KanjivgHalf half = KanjivgHalf::whole);

/// draw_shared_characters' characters alone.
[[nodiscard]] std::vector<char32_t> random_shared_characters(const CharacterLibrary& library,
                                                             const std::filesystem::path& folder,
                                                             std::size_t count, std::uint64_t seed,
                                                             const std::vector<char32_t>& excluded,
                                                             double form_tolerance_m = kSameFormFrechet_m,
                                                             KanjivgHalf half = KanjivgHalf::whole);

struct OtherHandMeasurement {
  std::vector<char32_t> characters;
  std::uint64_t seed = 0;
  /// How the characters were drawn (said in the markdown): the half, the form tolerance and the counts.
  KanjivgHalf half = KanjivgHalf::whole;
  double form_tolerance_m = kSameFormFrechet_m;
  SharedCharacters draw;
  std::uint32_t assist_after_misses =
      0;  ///< attempts a stroke gets before it is credited assisted (0: never)
  std::size_t strokes = 0;
  std::size_t strokes_first_attempt = 0;     ///< accepted at the first attempt
  std::size_t characters_first_attempt = 0;  ///< every stroke accepted at its first attempt
  std::size_t strokes_unassisted = 0;        ///< accepted within the attempts before assistance
  std::size_t characters_unassisted = 0;     ///< every stroke so
  std::size_t strokes_assisted = 0;          ///< credited assisted after assist_after_misses misses
  std::size_t characters_completed = 0;      ///< completed, assisted strokes included
  std::vector<std::string> refused;          ///< first examples of strokes refused at the first attempt
  /// Every kind of sim/person_traces.hpp made from the aligned KanjiVG lines instead of the medians.
  std::vector<KindAcceptance> kinds;
};

/// For each character, each stroke's KanjiVG line aligned (align_to_medians) is written by `pointer_trace`
/// and matched against the data's stroke (60 mm box, the renderer's start radius, `acceptance`); a
/// refused stroke is written again (a new draw of the same line) until it is accepted or has been refused
/// `assist_after_misses` times, when it is credited assisted, as in the trial (0: never assisted). Every
/// kind of person_trace is also made from the aligned lines. Deterministic for a seed.
[[nodiscard]] OtherHandMeasurement measure_other_hand(const CharacterLibrary& library,
                                                      const std::filesystem::path& folder,
                                                      const std::vector<char32_t>& characters,
                                                      std::uint64_t seed, std::uint32_t assist_after_misses,
                                                      const StrokeAcceptance& acceptance = {});

/// The markdown tables of the measurement, with the command that made it.
[[nodiscard]] std::string other_hand_markdown(const OtherHandMeasurement& measurement,
                                              const std::string& invocation);

}  // namespace calligraphy
