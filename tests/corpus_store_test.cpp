#include "calligraphy/model/corpus_store.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "model/corpus_store_format.hpp"

using namespace calligraphy;

namespace {

std::vector<Character> embedded_characters() {
  const CharacterLibrary library = CharacterLibrary::embedded();
  std::vector<Character> out;
  for (char32_t c : library.characters()) out.push_back(library.load(c));
  return out;
}

std::vector<Character> small_set() {
  const CharacterLibrary library = CharacterLibrary::embedded();
  return {library.load(U'永'), library.load(U'十')};
}

// Each character's outline paths as its embedded file gives them.
std::vector<std::vector<std::string>> outline_paths(const std::vector<Character>& characters) {
  const CharacterLibrary library = CharacterLibrary::embedded();
  std::vector<std::vector<std::string>> paths;
  for (const Character& c : characters) paths.push_back(library.load_outline_paths(c.code_point));
  return paths;
}

// Every load of every character and its outlines either succeeds or throws DataError.
void open_and_load_outlines(std::span<const std::uint8_t> bytes) {
  const CorpusStore store = CorpusStore::from_bytes(bytes, "test");
  for (char32_t cp : store.characters()) {
    (void)store.load(cp);
    (void)store.load_outline_paths(cp);
  }
}

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("calligraphy_store_test_" + name);
}

// Every load of every character either succeeds or throws DataError; nothing else escapes.
void open_and_load_all(std::span<const std::uint8_t> bytes) {
  const CorpusStore store = CorpusStore::from_bytes(bytes, "test");
  for (char32_t cp : store.characters()) (void)store.load(cp);
}

}  // namespace

TEST_CASE("CRC-32 matches the IEEE check value", "[store]") {
  const std::string text = "123456789";
  CHECK(store::crc32({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}) == 0xCBF43926u);
}

TEST_CASE("Store round trip of the embedded characters", "[store]") {
  const auto characters = embedded_characters();
  REQUIRE(characters.size() > 50);
  for (int steps : {1, 2, 16}) {
    CorpusStoreOptions options;
    options.steps_per_unit = steps;
    const auto bytes = encode_corpus_store(characters, options);
    const CorpusStore store = CorpusStore::from_bytes(bytes, "memory");
    REQUIRE(store.size() == characters.size());
    CHECK(store.info().steps_per_unit == steps);
    const double q = store.info().max_quantisation_error();
    CHECK(q == Approx(std::sqrt(2.0) / (2.0 * steps)));
    for (const Character& original : characters) {
      const Character loaded = store.load(original.code_point);
      REQUIRE(loaded.strokes.size() == original.strokes.size());
      for (std::size_t s = 0; s < original.strokes.size(); ++s) {
        const Stroke& a = original.strokes[s];
        const Stroke& b = loaded.strokes[s];
        CHECK(b.typical_id == a.typical_id);
        CHECK(b.attraction_factors == a.attraction_factors);
        CHECK(b.median == a.median);  // hanzi-writer-data's medians are integers: stored exactly
        REQUIRE(b.elements.size() == a.elements.size());
        for (std::size_t e = 0; e < a.elements.size(); ++e) {
          CHECK(b.elements[e].kind == a.elements[e].kind);
          REQUIRE(b.elements[e].degree == a.elements[e].degree);
          for (int i = 0; i <= a.elements[e].degree; ++i) {
            const auto k = static_cast<std::size_t>(i);
            CHECK((b.elements[e].control[k] - a.elements[e].control[k]).norm() <= q + 1e-12);
          }
          if (e > 0) CHECK(b.elements[e].start() == b.elements[e - 1].end());  // joints shared
        }
      }
    }
  }
}

TEST_CASE("A 1.0 store without medians is written on request and still read", "[store]") {
  const auto set = small_set();
  CorpusStoreOptions options;
  options.medians = false;
  const auto without = encode_corpus_store(set, options);
  const auto with = encode_corpus_store(set);
  const CorpusStore old_store = CorpusStore::from_bytes(without, "1.0");
  CHECK(old_store.info().version_minor == 0);
  CHECK_FALSE(old_store.info().medians);
  const CorpusStore new_store = CorpusStore::from_bytes(with, "1.1");
  CHECK(new_store.info().version_minor == 1);
  CHECK(new_store.info().medians);
  CHECK(with.size() > without.size());
  for (const Character& original : set) {
    const Character a = old_store.load(original.code_point);
    const Character b = new_store.load(original.code_point);
    REQUIRE(a.strokes.size() == b.strokes.size());
    for (std::size_t s = 0; s < a.strokes.size(); ++s) {
      CHECK(a.strokes[s].median.empty());
      CHECK(b.strokes[s].median == original.strokes[s].median);
      CHECK(a.strokes[s].elements.size() == b.strokes[s].elements.size());  // the same models
    }
  }
  // A store written before medians were stored (the fuzzer's seed, format 1.0) reads as it did.
  std::ifstream in(std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "fuzz/seeds/three_characters.clg",
                   std::ios::binary);
  const std::vector<std::uint8_t> seed((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
  const CorpusStore seed_store = CorpusStore::from_bytes(seed, "three_characters.clg");
  CHECK(seed_store.info().version_minor == 0);
  CHECK(seed_store.size() == 3);
  for (char32_t c : seed_store.characters()) {
    for (const Stroke& stroke : seed_store.load(c).strokes) CHECK(stroke.median.empty());
  }
}

TEST_CASE("Store medians: exact in any unit, every count coded, bounds refused", "[store]") {
  Character c = CharacterLibrary::embedded().load(U'十');
  c.strokes[0].median = {{100.4, 200.6}, {101.0, 199.0}};  // not in quarter units: float64
  c.strokes[1].median.clear();                             // a stroke without one
  std::vector<Vec2> long_median;
  for (int i = 0; i < 40; ++i) long_median.emplace_back(500 + i, -100 + 3 * i);  // past the 5-bit count
  Character d = CharacterLibrary::embedded().load(U'永');
  d.strokes[0].median = long_median;
  d.strokes[1].median = {{-50000.0, 90000.0}};                                // one point, far away
  d.strokes[2].median = {{388.25, 656.75}, {404.5, 372.75}, {400.0, 300.0}};  // quarter units: exact
  const std::vector<Character> set{c, d};
  const CorpusStore store = CorpusStore::from_bytes(encode_corpus_store(set), "memory");
  const Character lc = store.load(U'十');
  CHECK(lc.strokes[0].median == c.strokes[0].median);
  CHECK(lc.strokes[1].median.empty());
  const Character ld = store.load(U'永');
  CHECK(ld.strokes[0].median == long_median);
  CHECK(ld.strokes[1].median == std::vector<Vec2>{{-50000.0, 90000.0}});
  CHECK(ld.strokes[2].median == d.strokes[2].median);

  Character bad = c;
  bad.strokes[0].median[0].x() = std::nan("");
  CHECK_THROWS_WITH(encode_corpus_store(std::vector{bad}), Catch::Contains("median"));
  bad = c;
  bad.strokes[0].median[0].y() = 1e9;
  CHECK_THROWS_WITH(encode_corpus_store(std::vector{bad}), Catch::Contains("out of range"));
  bad = c;
  bad.strokes[0].median.assign(16384, Vec2(1.0, 2.0));
  CHECK_THROWS_WITH(encode_corpus_store(std::vector{bad}), Catch::Contains("16383"));
}

TEST_CASE("Store outlines: the same numbers back, compact or as text, and none where none were given",
          "[store]") {
  const std::vector<Character> characters = embedded_characters();
  const std::vector<std::vector<std::string>> paths = outline_paths(characters);
  const auto bytes = encode_corpus_store(characters, {}, paths);
  const CorpusStore store = CorpusStore::from_bytes(bytes, "memory");
  CHECK(store.info().version_minor == 2);
  CHECK(store.info().outlines);
  CHECK(store.info().medians);
  // hanzi-writer-data's paths are absolute commands in whole units: stored compactly, far below their text.
  std::size_t text_bytes = 0;
  for (const auto& character : paths) {
    for (const std::string& path : character) text_bytes += path.size();
  }
  CHECK(bytes.size() - encode_corpus_store(characters).size() < text_bytes / 2);
  for (std::size_t i = 0; i < characters.size(); ++i) {
    INFO(describe_character(characters[i].code_point));
    const std::vector<std::string> back = store.load_outline_paths(characters[i].code_point);
    REQUIRE(back.size() == paths[i].size());
    for (std::size_t s = 0; s < back.size(); ++s)
      CHECK(parse_svg_path(back[s]) == parse_svg_path(paths[i][s]));
  }

  // Paths not in the compact form (relative commands, S, decimals, an exponent, implicit repetition, two
  // subpaths, a '+') come back as their text; a character without outlines has none.
  Character shi = CharacterLibrary::embedded().load(U'十');
  Character yong = CharacterLibrary::embedded().load(U'永');
  Character ren = CharacterLibrary::embedded().load(U'人');
  const std::vector<std::string> odd = {"m 10 20 l 30 0 l 0 30 z", "M +1.5 2 L 40 2 L 40 40.25 Z"};
  REQUIRE(yong.strokes.size() == 5);
  const std::vector<std::string> more = {
      "M 0 0 C 10 0 20 10 20 20 S 30 40 0 40 Z", "M 0 0 L 1e2 0 L 100 100 Z", "M 0 0 L 50 0 50 50 Z",
      "M 0 0 L 9 0 L 9 9 Z M 20 20 L 30 20 L 30 30 Z", "M 0 0 L -100000 0 L 0 100000 Z"};
  const std::vector<std::vector<std::string>> forged = {odd, more, {}};
  const CorpusStore forged_store = CorpusStore::from_bytes(
      encode_corpus_store(std::vector<Character>{shi, yong, ren}, {}, forged), "forged");
  CHECK(forged_store.load_outline_paths(U'十') == odd);
  const std::vector<std::string> back = forged_store.load_outline_paths(U'永');
  REQUIRE(back.size() == more.size());
  for (std::size_t s = 0; s < back.size(); ++s) CHECK(parse_svg_path(back[s]) == parse_svg_path(more[s]));
  CHECK(back.back() == "M 0 0 L -100000 0 L 0 100000 Z");  // compact: whole units within the bound
  CHECK(forged_store.load_outline_paths(U'人').empty());

  // Asked not to, or given none, the writer writes a 1.1 store, which has none to give.
  CorpusStoreOptions options;
  options.outlines = false;
  for (const auto& without :
       {encode_corpus_store(characters, options, paths), encode_corpus_store(characters)}) {
    const CorpusStore plain = CorpusStore::from_bytes(without, "plain");
    CHECK(plain.info().version_minor == 1);
    CHECK_FALSE(plain.info().outlines);
    CHECK(plain.load_outline_paths(U'永').empty());
  }
  // What it cannot store is refused, naming the character.
  CHECK_THROWS_AS(encode_corpus_store(characters, {}, std::vector<std::vector<std::string>>(2)),
                  InvalidArgument);
  CHECK_THROWS_WITH(encode_corpus_store(std::vector<Character>{shi}, {},
                                        std::vector<std::vector<std::string>>{{"M 0 0 L 1 1 L 0 1 Z"}}),
                    Catch::Contains("U+5341") && Catch::Contains("1 outlines for 2 strokes"));
  CHECK_THROWS_WITH(encode_corpus_store(std::vector<Character>{shi}, {},
                                        std::vector<std::vector<std::string>>{
                                            {std::string(1 << 20, ' '), "M 0 0 L 1 1 L 0 1 Z"}}),
                    Catch::Contains("1,048,575"));
}

TEST_CASE("Store with outlines cut at every byte or with any byte changed is a DataError", "[store]") {
  const std::vector<Character> set = small_set();
  const auto bytes = encode_corpus_store(set, {}, outline_paths(set));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    INFO("truncated to " << n << " of " << bytes.size() << " bytes");
    CHECK_THROWS_AS(open_and_load_outlines(std::span(bytes).first(n)), DataError);
  }
  CHECK_NOTHROW(open_and_load_outlines(bytes));
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    auto corrupted = bytes;
    corrupted[i] ^= 0x10;
    INFO("byte " << i);
    CHECK_THROWS_AS(open_and_load_outlines(corrupted), DataError);
  }
}

TEST_CASE("Store with an unknown header flag is refused naming the file and the offset", "[store]") {
  auto bytes = encode_corpus_store(small_set());
  store::put_u32(bytes.data() + store::kOffFlags, store::kFlagMedians | 4u);
  store::put_u32(bytes.data() + store::kOffHeaderCrc,
                 store::crc32(std::span(bytes).first(store::kOffHeaderCrc)));
  CHECK_THROWS_WITH(CorpusStore::from_bytes(bytes, "flags.clg"),
                    Catch::Contains("flags.clg: offset 28") && Catch::Contains("unknown flags"));
}

TEST_CASE("Store keeps explicit attraction factors and detached elements exactly", "[store]") {
  Character c = CharacterLibrary::embedded().load(U'永');
  c.strokes[1].attraction_factors[1] = 0.123456789;
  c.strokes[2].elements[1].control[0] += Vec2(3.0, -4.0);  // an element that does not start at the joint
  if (c.strokes[2].elements[1].degree == 1) c.strokes[2].elements[1].kind = ElementKind::line;
  const std::vector<Character> one{c};
  const auto bytes = encode_corpus_store(one, {16, 10.0});
  const Character loaded = CorpusStore::from_bytes(bytes, "memory").load(U'永');
  CHECK(loaded.strokes[1].attraction_factors == c.strokes[1].attraction_factors);
  CHECK((loaded.strokes[2].elements[1].start() - c.strokes[2].elements[1].start()).norm() <= 1.0 / 16);
  CHECK((loaded.strokes[2].elements[0].end() - c.strokes[2].elements[0].end()).norm() <= 1.0 / 16);
}

TEST_CASE("Store lookup of present and absent characters", "[store]") {
  const auto path = temp_path("lookup.clg");
  write_corpus_store(path, small_set());
  const CorpusStore store = CorpusStore::open(path);
  CHECK(store.characters() == std::vector<char32_t>{U'十', U'永'});
  CHECK(store.contains(U'永'));
  CHECK_FALSE(store.contains(U'二'));
  CHECK(store.load(U'十').strokes.size() == 2);
  CHECK(store.load(U'永').source.find(path.string()) == 0);
  CHECK_THROWS_AS(store.load(U'二'), CharacterNotFound);
  CHECK_THROWS_WITH(store.load(U'二'), Catch::Contains("U+4E8C") && Catch::Contains(path.string()));
  CHECK_THROWS_AS(store.record_bytes(U'二'), CharacterNotFound);
  CHECK(store.record_bytes(U'永') > 10);
  std::filesystem::remove(path);
}

TEST_CASE("A store cut or replaced by another program after it was opened loads as it was", "[store]") {
  // Read whole when opened: a mapping of a file cut under it would end the process (SIGBUS) at the next load.
  const auto path = temp_path("cut_after_open.clg");
  write_corpus_store(path, small_set());
  const CorpusStore store = CorpusStore::open(path);
  const std::size_t yong_strokes = store.load(U'永').strokes.size();
  std::filesystem::resize_file(path, 0);
  CHECK(store.load(U'永').strokes.size() == yong_strokes);
  CHECK(store.load(U'十').strokes.size() == 2);
  std::filesystem::remove(path);
  CHECK(store.characters() == std::vector<char32_t>{U'十', U'永'});
}

TEST_CASE("Store writer rejects what it cannot encode", "[store]") {
  const auto set = small_set();
  CHECK_THROWS_AS(encode_corpus_store(set, {3, 10.0}), InvalidArgument);
  std::vector<Character> twice{set[0], set[0]};
  CHECK_THROWS_AS(encode_corpus_store(twice, {}), InvalidArgument);
  Character bad = set[0];
  bad.strokes[0].typical_id = 40;
  CHECK_THROWS_AS(encode_corpus_store(std::vector{bad}, {}), InvalidArgument);
  bad = set[0];
  bad.strokes[0].elements[0].control[0].x() = std::nan("");
  CHECK_THROWS_AS(encode_corpus_store(std::vector{bad}, {}), InvalidArgument);
  bad = set[0];
  bad.strokes[0].attraction_factors.pop_back();
  CHECK_THROWS_AS(encode_corpus_store(std::vector{bad}, {}), InvalidArgument);
}

TEST_CASE("Store: missing, empty, foreign and newer-version files are DataErrors naming the file",
          "[store]") {
  CHECK_THROWS_AS(CorpusStore::open(temp_path("does_not_exist.clg")), DataError);
  const auto empty = temp_path("empty.clg");
  std::ofstream(empty).close();
  CHECK_THROWS_WITH(CorpusStore::open(empty),
                    Catch::Contains(empty.string()) && Catch::Contains("too short"));
  std::filesystem::remove(empty);
  const std::string json = R"({"strokes": [], "medians": []})";
  std::vector<std::uint8_t> foreign(json.begin(), json.end());
  foreign.resize(600, ' ');
  CHECK_THROWS_WITH(CorpusStore::from_bytes(foreign, "x.json"),
                    Catch::Contains("x.json") && Catch::Contains("magic"));

  auto bytes = encode_corpus_store(small_set());
  store::put_u16(bytes.data() + store::kOffVersionMajor, 2);  // a future format, header CRC fixed up
  store::put_u32(bytes.data() + store::kOffHeaderCrc,
                 store::crc32(std::span(bytes).first(store::kOffHeaderCrc)));
  CHECK_THROWS_WITH(CorpusStore::from_bytes(bytes, "v2"),
                    Catch::Contains("format version 2.1 is not supported"));
}

TEST_CASE("Store truncated at every byte offset is a DataError", "[store]") {
  const auto bytes = encode_corpus_store(small_set());
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    INFO("truncated to " << n << " of " << bytes.size() << " bytes");
    CHECK_THROWS_AS(open_and_load_all(std::span(bytes).first(n)), DataError);
  }
  CHECK_NOTHROW(open_and_load_all(bytes));
}

TEST_CASE("Store with any single byte corrupted is a DataError", "[store]") {
  const auto bytes = encode_corpus_store(small_set());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (std::uint8_t flip : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
      auto corrupted = bytes;
      corrupted[i] ^= flip;
      INFO("byte " << i << " xor " << int{flip});
      // CRC-32 detects every error burst of up to 32 bits, so each such change is caught.
      CHECK_THROWS_AS(open_and_load_all(corrupted), DataError);
    }
  }
}

TEST_CASE("Store regressions from fuzzing are DataErrors, not crashes", "[store]") {
  const std::filesystem::path folder = std::filesystem::path(CALLIGRAPHY_TEST_DATA_DIR) / "store_regressions";
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() == ".md") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    INFO(entry.path().string());
    CHECK_THROWS_AS(open_and_load_all(bytes), DataError);
    ++files;
  }
  CHECK(files > 0);
}

TEST_CASE("A scene laid out from a store matches one from the fitted characters", "[store]") {
  const auto set = small_set();
  const CorpusStore store = CorpusStore::from_bytes(encode_corpus_store(set, {16, 10.0}), "memory");
  const Scene from_json = Scene::lay_out(set);
  const Scene from_store = Scene::lay_out({store.load(U'永'), store.load(U'十')});
  REQUIRE(from_store.stroke_count() == from_json.stroke_count());
  const double metres_per_unit = SceneLayout{}.character_size_m / kDataBoxSize;
  for (std::size_t c = 0; c < 2; ++c) {
    for (std::size_t s = 0; s < from_json.characters[c].strokes.size(); ++s) {
      const auto& a = from_json.characters[c].strokes[s];
      const auto& b = from_store.characters[c].strokes[s];
      CHECK(a.typical_id == b.typical_id);
      CHECK(b.length_m() == Approx(a.length_m()).epsilon(1e-3));
      CHECK((a.start() - b.start()).norm() <=
            store.info().max_quantisation_error() * metres_per_unit + 1e-15);
    }
  }
}

TEST_CASE("Store statistics count what was written and report bad records", "[store]") {
  const auto characters = embedded_characters();
  auto bytes = encode_corpus_store(characters);
  std::size_t strokes = 0;
  std::size_t elements = 0;
  std::map<int, std::size_t> by_id;
  for (const auto& c : characters) {
    strokes += c.strokes.size();
    for (const auto& s : c.strokes) {
      elements += s.elements.size();
      ++by_id[s.typical_id];
    }
  }
  const CorpusStoreStats stats = corpus_store_stats(CorpusStore::from_bytes(bytes, "memory"));
  CHECK(stats.characters == characters.size());
  CHECK(stats.strokes == strokes);
  CHECK(stats.elements == elements);
  CHECK(stats.strokes_by_typical_id == by_id);
  CHECK(stats.errors.empty());

  bytes.back() ^= 0x10;  // the last record: its CRC no longer matches, the others still load
  const CorpusStoreStats bad = corpus_store_stats(CorpusStore::from_bytes(bytes, "memory"));
  CHECK(bad.characters == characters.size() - 1);
  REQUIRE(bad.errors.size() == 1);
  CHECK_THAT(bad.errors[0], Catch::Contains("checksum mismatch"));
}
