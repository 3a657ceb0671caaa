// The corpus store compiled into the library (data/corpus) and the standard character set that falls back
// to it: every hanzi-writer-data character, with its medians, and no file read.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"
#include "corpus_folder.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;

namespace {

const std::filesystem::path kStoreFile =
    std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "data/corpus/hanzi-writer-data-2.0.1.clg";

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Characters of the bundled store that are not embedded, drawn at random (fixed seed): none is named in
// any test, so the fallback is not tested on a hand-picked few.
std::vector<char32_t> random_store_characters(std::size_t count) {
  const std::vector<char32_t> embedded = CharacterLibrary::embedded().characters();
  std::vector<char32_t> pool;
  for (char32_t c : CorpusStore::bundled().characters()) {
    if (std::find(embedded.begin(), embedded.end(), c) == embedded.end()) pool.push_back(c);
  }
  std::mt19937_64 random(20261126);
  std::shuffle(pool.begin(), pool.end(), random);
  pool.resize(count);
  return pool;
}

}  // namespace

TEST_CASE("The bundled store holds every hanzi-writer-data character with its medians and outlines",
          "[store][bundled]") {
  const CorpusStore& store = CorpusStore::bundled();
  CHECK(store.size() == 9574);
  CHECK(store.info().version_major == 1);
  CHECK(store.info().version_minor == 2);
  CHECK(store.info().medians);
  CHECK(store.info().outlines);
  CHECK(store.info().steps_per_unit == CorpusStoreOptions{}.steps_per_unit);
  CHECK(store.name() == "bundled:hanzi-writer-data-2.0.1.clg");
  CHECK(std::string(CorpusStore::bundled_sha256()).size() == 64);
  for (char32_t c : CharacterLibrary::embedded().characters()) CHECK(store.contains(c));
  // The file in the repository is what the library bundles.
  const CorpusStore file = CorpusStore::open(kStoreFile);
  CHECK(file.info().file_bytes == store.info().file_bytes);
  CHECK(file.characters() == store.characters());
}

TEST_CASE("The standard set loads characters beyond the embedded ones from the bundled store",
          "[store][bundled]") {
  const CharacterLibrary standard = CharacterLibrary::standard();
  const CharacterLibrary embedded = CharacterLibrary::embedded();
  CHECK(standard.characters().size() == 9574);
  CHECK(standard.description().find("(9574: 58 embedded, the others from the bundled corpus store)") !=
        std::string::npos);
  for (char32_t c : random_store_characters(6)) {
    INFO(describe_character(c));
    CHECK_FALSE(embedded.contains(c));
    REQUIRE(standard.contains(c));
    const Character character = standard.load(c);
    CHECK(character.code_point == c);
    CHECK(character.source.find("bundled:hanzi-writer-data-2.0.1.clg#") == 0);
    REQUIRE_FALSE(character.strokes.empty());
    const CharacterData data = standard.load_data(c);
    REQUIRE(data.medians.size() == character.strokes.size());
    for (std::size_t s = 0; s < character.strokes.size(); ++s) {
      const Stroke& stroke = character.strokes[s];
      CHECK(stroke.median.size() >= 2);
      CHECK(stroke.median == data.medians[s]);
      // The elements were fitted to that median: their ends lie near its ends (tolerance 10 units plus
      // the brush hooks the fitter trims, far less than a stroke's length).
      CHECK((stroke.feature_point(0) - stroke.median.front()).norm() < 120.0);
      CHECK((stroke.feature_point(stroke.feature_point_count() - 1) - stroke.median.back()).norm() < 120.0);
    }
    // A scene follows the medians, as for an embedded character (docs/stroke-acceptance.md).
    const Scene scene = Scene::lay_out({character});
    for (const auto& placed : scene.characters[0].strokes) CHECK(placed.median_m.size() >= 2);
    // Drawn as Hanzi Writer draws it: one filled outline per stroke, around that stroke's median.
    const CharacterOutlines outlines = standard.load_outlines(c);
    CHECK(outlines.source.find("bundled:hanzi-writer-data-2.0.1.clg#") == 0);
    REQUIRE(outlines.strokes.size() == character.strokes.size());
    for (std::size_t s = 0; s < outlines.strokes.size(); ++s) {
      INFO("stroke " << s + 1);
      REQUIRE_FALSE(outlines.strokes[s].empty());
      const auto inside = [&](const Vec2& p) {
        return std::any_of(outlines.strokes[s].begin(), outlines.strokes[s].end(),
                           [&](const OutlinePolygon& polygon) { return polygon_contains(polygon, p); });
      };
      const std::vector<Vec2>& median = character.strokes[s].median;
      CHECK(inside(median[median.size() / 2]));
    }
  }
  // An embedded character is still fitted from its JSON file, with its outlines.
  CHECK(standard.load(U'永').source == embedded.load(U'永').source);
  CHECK_FALSE(standard.load_outlines(U'永').strokes.empty());
  // A character of no set is named with the store it was looked for in.
  CHECK_THROWS_AS(standard.load(U'A'), CharacterNotFound);
  CHECK_THROWS_WITH(standard.load(U'A'), Catch::Contains("U+0041") && Catch::Contains("bundled:"));
  CHECK_FALSE(standard.contains(U'A'));
}

TEST_CASE("A copy of the store file truncated or damaged is refused naming the file", "[store][bundled]") {
  const std::vector<std::uint8_t> bytes = read_bytes(kStoreFile);
  REQUIRE(bytes.size() > 100000);
  const auto path = std::filesystem::temp_directory_path() / "calligraphy_bundled_store_test.clg";
  const auto write = [&](std::span<const std::uint8_t> content) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(content.data()), static_cast<std::streamsize>(content.size()));
  };
  // Cut in the header, in the index, in the records, and one byte short.
  for (std::size_t n :
       {std::size_t{10}, std::size_t{63}, std::size_t{5000}, bytes.size() / 2, bytes.size() - 1}) {
    INFO("cut to " << n << " bytes");
    write(std::span(bytes).first(n));
    CHECK_THROWS_AS(CorpusStore::open(path), DataError);
    CHECK_THROWS_WITH(CorpusStore::open(path), Catch::Contains(path.string()));
  }
  // A damaged record is found when its character is loaded, naming the file and the character.
  std::vector<std::uint8_t> damaged = bytes;
  damaged[damaged.size() - 3] ^= 0x5A;  // inside the last character's record
  write(damaged);
  const CorpusStore store = CorpusStore::open(path);
  const char32_t last = store.characters().back();
  CHECK_THROWS_WITH(store.load(last), Catch::Contains(path.string()) &&
                                          Catch::Contains("checksum mismatch") &&
                                          Catch::Contains(describe_character(last)));
  // A damaged index is refused when the file is opened.
  damaged = bytes;
  damaged[700] ^= 0x01;
  write(damaged);
  CHECK_THROWS_WITH(CorpusStore::open(path), Catch::Contains(path.string()) && Catch::Contains("checksum"));
  std::filesystem::remove(path);
}

TEST_CASE(
    "The bundled store's medians and outlines are hanzi-writer-data's, exactly, for every character of the "
    "package",
    "[store][bundled]") {
  // The whole package where scripts/test.sh fetched it, else the sample in tests/data (said on stdout).
  const CharacterLibrary package = CharacterLibrary::from_directory(testing::corpus_folder());
  const CorpusStore& store = CorpusStore::bundled();
  std::size_t compared = 0;
  // Under the sanitizers a random 1,000 of them (tests/test_sizing.hpp): the same reader on fewer characters.
  for (char32_t c : testing::sanitizer_subset(package.characters(), 1000, "package characters")) {
    INFO(describe_character(c));
    REQUIRE(store.contains(c));
    const CharacterData data = package.load_data(c);
    const Character stored = store.load(c);
    REQUIRE(stored.strokes.size() == data.medians.size());
    for (std::size_t s = 0; s < data.medians.size(); ++s) {
      if (stored.strokes[s].median != data.medians[s]) FAIL("stroke " << s + 1 << ": the median differs");
    }
    // The outlines: the same numbers as the file's paths (compact or as text), so the same polygons.
    const std::vector<std::string> paths = package.load_outline_paths(c);
    const std::vector<std::string> stored_paths = store.load_outline_paths(c);
    REQUIRE(stored_paths.size() == paths.size());
    for (std::size_t s = 0; s < paths.size(); ++s) {
      if (parse_svg_path(stored_paths[s]) != parse_svg_path(paths[s]))
        FAIL("stroke " << s + 1 << ": the outline differs");
    }
    ++compared;
  }
  CHECK(compared >= 100);
}
