#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/fitting.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "parameter_table_walk.hpp"

using namespace calligraphy;

TEST_CASE("39 typical strokes with stable IDs", "[model]") {
  REQUIRE(typical_strokes().size() == 39);
  for (std::size_t i = 0; i < 39; ++i) CHECK(typical_strokes()[i].id == static_cast<int>(i) + 1);
  CHECK(typical_stroke(10).acronym == "HZG");
  CHECK(typical_stroke(10).unicode == U'\u31C6');
  CHECK(typical_stroke_id("XG") == 30);
  CHECK_THROWS_AS(typical_stroke(40), InvalidArgument);
}

TEST_CASE("A typical stroke by what a person calls it: acronym in any case, Chinese name, stroke character",
          "[model]") {
  CHECK(typical_stroke_id_by_name("HZG") == 10);
  CHECK(typical_stroke_id_by_name("hzg") == 10);
  CHECK(typical_stroke_id_by_name("hZg") == 10);
  CHECK(typical_stroke_id_by_name("横折钩") == 10);
  CHECK(typical_stroke_id_by_name("\u31C6") == 10);
  CHECK_FALSE(typical_stroke_id_by_name("10").has_value());  // an ID is a number, read by the caller
  CHECK_FALSE(typical_stroke_id_by_name("").has_value());
  CHECK_FALSE(typical_stroke_id_by_name("HZGX").has_value());
  CHECK_FALSE(typical_stroke_id("hzg").has_value());  // the data's acronyms are exact
  for (const TypicalStroke& t : typical_strokes()) {
    CHECK(typical_stroke_id_by_name(t.acronym) == t.id);
    CHECK(typical_stroke_id_by_name(t.name_zh) == t.id);
  }
}

TEST_CASE("Fitting: a straight median is one LSE, a corner makes a feature point", "[model]") {
  const std::vector<Vec2> straight = {{100, 500}, {300, 502}, {600, 500}};
  auto f = fit_stroke(straight);
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK(f.stroke.elements[0].kind == ElementKind::line);
  CHECK(f.stroke.typical_id == typical_stroke_id("H"));

  const std::vector<Vec2> corner = {{100, 600}, {400, 610}, {700, 620}, {700, 300}, {700, 100}};
  f = fit_stroke(corner);
  REQUIRE(f.stroke.elements.size() == 2);
  CHECK(f.stroke.feature_point(1).isApprox(Vec2(700, 620)));
  CHECK(f.stroke.typical_id == typical_stroke_id("HZ"));
  CHECK(f.stroke.attraction_factors.size() == 3);

  const std::vector<Vec2> bend = {{300, 700}, {300, 400}, {320, 300}, {380, 230}, {500, 200}, {700, 200}};
  f = fit_stroke(bend);
  CHECK(f.max_deviation <= FitOptions{}.tolerance + 1e-9);
  bool has_curve = false;
  for (const auto& e : f.stroke.elements) has_curve |= e.kind == ElementKind::bezier;
  CHECK(has_curve);

  const std::vector<Vec2> dot = {{500, 500}};
  f = fit_stroke(dot);
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK(f.stroke.elements[0].start() == f.stroke.elements[0].end());  // rule (d)
}

TEST_CASE("永 is modelled as 5 typical strokes: D HZG HP P N", "[model]") {
  const Character c = CharacterLibrary::embedded().load(U'永');
  REQUIRE(c.strokes.size() == 5);
  std::vector<std::string_view> acronyms;
  for (const auto& s : c.strokes) acronyms.push_back(typical_stroke(s.typical_id).acronym);
  CHECK(acronyms == std::vector<std::string_view>{"D", "HZG", "HP", "P", "N"});
  const CharacterTable table = character_table(c);
  std::size_t elements = 0;
  for (const auto& s : c.strokes) elements += s.elements.size();
  CHECK(table.feature_point_count() == elements + c.strokes.size());
  for (std::size_t s = 0; s < c.strokes.size(); ++s) {  // feature points index the control points
    for (std::size_t k = 0; k < table.feature_point_indices[s].size(); ++k) {
      const int i = table.feature_point_indices[s][k];
      CHECK(table.control_points[static_cast<std::size_t>(i)] == c.strokes[s].feature_point(k));
    }
  }
}

TEST_CASE("Every embedded character loads and fits within tolerance", "[model]") {
  const auto library = CharacterLibrary::embedded();
  const auto chars = library.characters();
  CHECK(chars.size() >= 40);
  for (char32_t cp : chars) {
    const auto data = library.load_data(cp);
    for (const auto& median : data.medians) {
      const auto fitted = fit_stroke(median);
      INFO(describe_character(cp));
      CHECK(fitted.max_deviation <= 2.0 * FitOptions{}.tolerance);
    }
  }
}

namespace {
std::filesystem::path scratch_folder(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("calligraphy-test-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}
void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }
}  // namespace

TEST_CASE("Bad data gives errors that name the character, the path and the position", "[model][errors]") {
  CHECK_THROWS_AS(CharacterLibrary::from_directory("/nonexistent/hanzi"), DataError);
  CHECK_THROWS_WITH(CharacterLibrary::from_directory("/nonexistent/hanzi"),
                    Catch::Contains("/nonexistent/hanzi"));

  CHECK_THROWS_AS(CharacterLibrary::embedded().load(U'龘'), CharacterNotFound);
  CHECK_THROWS_WITH(CharacterLibrary::embedded().load(U'龘'), Catch::Contains("U+9F98"));

  const auto dir = scratch_folder("bad");
  write(dir / "一.json", "{\"medians\": [[[1, 2], [3, 4]],\n  [[5, 6], [7,]]]}");
  CHECK_THROWS_AS(CharacterLibrary::from_directory(dir).load(U'一'), DataError);
  CHECK_THROWS_WITH(CharacterLibrary::from_directory(dir).load(U'一'),
                    Catch::Contains("一.json") && Catch::Contains("U+4E00") && Catch::Contains("2:"));
  write(dir / "二.json", "{\"medians\": [[[1, 2], [3, \"x\"]]]}");
  CHECK_THROWS_WITH(CharacterLibrary::from_directory(dir).load(U'二'), Catch::Contains("/medians/0/1"));
  write(dir / "三.json", "{\"strokes\": []}");
  CHECK_THROWS_WITH(CharacterLibrary::from_directory(dir).load(U'三'), Catch::Contains("/medians"));
  write(dir / "四.json", "");
  CHECK_THROWS_AS(CharacterLibrary::from_directory(dir).load(U'四'), DataError);
  CHECK_THROWS_AS(CharacterLibrary::from_directory(dir).load(U'五'), CharacterNotFound);
  std::filesystem::remove_all(dir);
}

TEST_CASE("The loader reads a hanzi-writer-data folder the same as the embedded set", "[model]") {
  const auto dir = scratch_folder("copy");
  std::filesystem::copy_file(std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "data/hanzi-writer-data/永.json",
                             dir / "永.json");
  const auto from_folder = CharacterLibrary::from_directory(dir).load_data(U'永');
  const auto embedded = CharacterLibrary::embedded().load_data(U'永');
  CHECK(from_folder.medians == embedded.medians);
  std::filesystem::remove_all(dir);
}

TEST_CASE("UTF-8 round trip and malformed input", "[model]") {
  CHECK(decode_utf8("永我") == U"永我");
  CHECK(encode_utf8(U'永') == "永");
  CHECK_THROWS_AS(decode_utf8("\xE6\xB0"), InvalidArgument);
  CHECK_THROWS_AS(decode_utf8("\xC0\x80"), InvalidArgument);
  // The message shows the bytes at fault, from the sequence's first byte through the one that broke it.
  CHECK_THROWS_WITH(decode_utf8("a\xE6\xB0"), "malformed UTF-8 at byte 1 (\\xe6\\xb0): truncated sequence");
  CHECK_THROWS_WITH(decode_utf8("\xE6\xB0"
                                "b"),
                    Catch::Contains("(\\xe6\\xb0\\x62): invalid continuation byte"));
  CHECK_THROWS_WITH(decode_utf8("\xED\xA0\x80"),
                    Catch::Contains("(\\xed\\xa0\\x80): not a Unicode scalar value"));
  CHECK_THROWS_WITH(decode_utf8("\xFF"), Catch::Contains("(\\xff): invalid lead byte"));
  CHECK(describe_characters(U"永\uFE00") == "永 (U+6C38), \uFE00 (U+FE00)");
  CHECK(describe_characters(U"一二三", 2) == "一 (U+4E00), 二 (U+4E8C), ... (1 more)");
  // A NUL would cut the message short wherever it passes through a C string (an exception's what()).
  CHECK(describe_character(U'\0') == "(U+0000)");
  CHECK(describe_characters(std::u32string(U"\0一", 2)) == "(U+0000), 一 (U+4E00)");
}

TEST_CASE("A scene holds at most kMaxSceneCharacters characters", "[model]") {
  const Character yong = CharacterLibrary::embedded().load(U'永');
  CHECK(Scene::lay_out(std::vector<Character>(kMaxSceneCharacters, yong)).characters.size() ==
        kMaxSceneCharacters);
  CHECK_THROWS_WITH(Scene::lay_out(std::vector<Character>(kMaxSceneCharacters + 1, yong)),
                    Catch::Contains("1001 characters") && Catch::Contains("limit of 1000"));
  CHECK_NOTHROW(check_scene_size(kMaxSceneCharacters, "CHARS"));
  CHECK_THROWS_WITH(check_scene_size(100000, "CHARS"), Catch::StartsWith("CHARS: 100000 characters"));
}

TEST_CASE("A scene's layout lengths have finite bounds", "[model]") {
  const std::vector<Character> one{CharacterLibrary::embedded().load(U'十')};
  const auto laid_out = [&](double SceneLayout::*field, double value) {
    SceneLayout layout;
    layout.*field = value;
    return Scene::lay_out(one, layout);
  };
  for (const auto& [field, name, bound] :
       {std::tuple{&SceneLayout::box_margin_m, "box_margin_m", kMaxLayoutMarginM},
        std::tuple{&SceneLayout::start_radius_m, "start_radius_m", kMaxLayoutMarginM},
        std::tuple{&SceneLayout::character_size_m, "character_size_m", kMaxLayoutSizeM},
        std::tuple{&SceneLayout::spacing_m, "spacing_m", kMaxLayoutSizeM}}) {
    INFO(name);
    CHECK_NOTHROW(laid_out(field, bound));
    CHECK_THROWS_WITH(laid_out(field, 1e308), Catch::Contains(name) && Catch::Contains("out of range"));
    CHECK_THROWS_AS(laid_out(field, std::nextafter(bound, 1.0e9)), InvalidArgument);
  }
}

TEST_CASE("FitOptions' table: defaults in range, each bound refused by name", "[model]") {
  const std::vector<Vec2> median{Vec2(0, 0), Vec2(100, 0), Vec2(100, 100)};
  check_table_through<FitOptions>([&](const FitOptions& options) { (void)fit_stroke(median, options); });
  FitOptions degree;
  degree.max_degree = kMaxElementDegree + 1;
  CHECK_THROWS_WITH(fit_stroke(median, degree),
                    Catch::Contains("FitOptions.max_degree = 5 must be in [2, 4]"));
}
