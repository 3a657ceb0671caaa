// The 39 typical strokes, their classification against cnchar-order's labels, the robustness of the
// fitting to hanzi-writer-data's quirks (brush hooks, rounded corners), and the Fig. 13 drawing of a model.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/fitting.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/report/model_svg.hpp"
#include "eval/cnchar_validation.hpp"
#include "calligraphy/report/typical_strokes_report.hpp"

using namespace calligraphy;

namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + what.size())) ++n;
  return n;
}

int typical(std::string_view acronym) { return typical_stroke_id(acronym).value(); }

}  // namespace

TEST_CASE("Typical strokes: unique acronyms and code points, Unicode block facts", "[strokes]") {
  std::set<std::string_view> acronyms;
  std::set<char32_t> code_points;
  for (const TypicalStroke& t : typical_strokes()) {
    INFO(t.acronym);
    CHECK(acronyms.insert(t.acronym).second);
    if (t.unicode != 0) {
      CHECK(code_points.insert(t.unicode).second);
      CHECK(t.unicode >= U'\u31C0');
      CHECK(t.unicode <= U'\u31E5');
    }
    CHECK(!t.name_zh.empty());
    CHECK(!t.pinyin.empty());
    REQUIRE(!t.pieces.empty());
    CHECK(!t.pieces.front().hook);  // no stroke starts with its hook
    if (!t.compound) CHECK(t.pieces.size() == 1);
    for (const auto& p : t.pieces) {
      CHECK(p.start_tolerance_deg > 0.0);
      CHECK(p.end_tolerance_deg > 0.0);
      CHECK(p.min_length <= p.max_length);
    }
    CHECK(t.default_attraction > 0.0);
    CHECK(t.corner_attraction > 0.0);
  }
  // The Unicode CJK Strokes block (U+31C0-U+31E3, plus U+31E4 and U+31E5 added in Unicode 16).
  const std::pair<const char*, char32_t> block[] = {
      {"T", U'\u31C0'},   {"WG", U'\u31C1'},   {"XG", U'\u31C2'},    {"BXG", U'\u31C3'},  {"SW", U'\u31C4'},
      {"HZZ", U'\u31C5'}, {"HZG", U'\u31C6'},  {"HP", U'\u31C7'},    {"HZWG", U'\u31C8'}, {"SZWG", U'\u31C9'},
      {"HZT", U'\u31CA'}, {"HZZP", U'\u31CB'}, {"HPWG", U'\u31CC'},  {"HZW", U'\u31CD'},  {"HZZZ", U'\u31CE'},
      {"N", U'\u31CF'},   {"H", U'\u31D0'},    {"S", U'\u31D1'},     {"P", U'\u31D2'},    {"SP", U'\u31D3'},
      {"D", U'\u31D4'},   {"HZ", U'\u31D5'},   {"HG", U'\u31D6'},    {"SZ", U'\u31D7'},   {"SWZ", U'\u31D8'},
      {"ST", U'\u31D9'},  {"SG", U'\u31DA'},   {"PD", U'\u31DB'},    {"PZ", U'\u31DC'},   {"TN", U'\u31DD'},
      {"SZZ", U'\u31DE'}, {"SWG", U'\u31DF'},  {"HZZZG", U'\u31E1'}, {"PG", U'\u31E2'},   {"HXG", U'\u31E4'},
      {"SZP", U'\u31E5'}};
  for (const auto& [acronym, cp] : block) {
    INFO(acronym);
    CHECK(typical_stroke(typical(acronym)).unicode == cp);
  }
  // The 6 flat strokes are basic; the 25 turning strokes of GF 2001-2001 (IDs 7-31) compound.
  for (int id = 1; id <= 6; ++id) CHECK_FALSE(typical_stroke(id).compound);
  for (int id = 7; id <= 31; ++id) CHECK(typical_stroke(id).compound);
  CHECK(typical_stroke(typical("HZZZG")).name_zh == "横折折折钩");
  CHECK(typical_stroke(typical("SZWG")).name_zh == "竖折折钩");
  CHECK(typical_stroke(typical("HZG")).pieces.size() == 3);
}

TEST_CASE("docs/typical-strokes.md is what 'calligraphy strokes --markdown' generates", "[strokes]") {
  const std::string committed =
      read_text(std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "docs/typical-strokes.md");
  CHECK(committed == typical_strokes_markdown());
  const auto json = nlohmann::json::parse(typical_strokes_json());
  REQUIRE(json.size() == 39);
  CHECK(json[9]["acronym"] == "HZG");
  CHECK(json[9]["unicode"] == "U+31C6");
  CHECK(json[32]["unicode"].is_null());  // 左点 has no code point
  CHECK(count(typical_strokes_text(), "\n") == 40);
}

TEST_CASE("cnchar letters: every ID maps to one of cnchar's 26 letters, each letter reached", "[classify]") {
  std::set<char> letters;
  for (const TypicalStroke& t : typical_strokes()) letters.insert(cli::cnchar_letter(t.id));
  CHECK(letters.size() == 26);
  for (char l : letters) CHECK(cli::cnchar_letter_name(l) != "?");
  CHECK(cli::cnchar_letter(typical("HZG")) == 'r');
  CHECK(cli::cnchar_letter(typical("HG")) == 'e');
  CHECK_THROWS_AS(cli::cnchar_letter(0), InvalidArgument);
}

TEST_CASE("cnchar map parser reads the minified JavaScript form and JSON, rejects foreign text",
          "[classify]") {
  const auto orders = cli::parse_cnchar_orders(
      "x=JSON.parse('{\"一\":\"j\",\"永\":\"kresl\",\"a\":\"b\",\"乙\":\"o\"}');{\"j\":{\"shape\":\"一\"}}",
      "test.js");
  CHECK(orders.size() == 3);
  CHECK(orders.at(U'永') == "kresl");
  CHECK(cli::parse_cnchar_orders("{\n\"七\": \"ju\"\n}", "test.json").at(U'七') == "ju");
  CHECK_THROWS_AS(cli::parse_cnchar_orders("not a stroke map", "foreign.txt"), DataError);
  CHECK_THROWS_WITH(cli::parse_cnchar_orders("", "foreign.txt"), Catch::Contains("foreign.txt"));
}

TEST_CASE("Classification agrees with cnchar-order on fixed labelled samples", "[classify]") {
  const std::filesystem::path data(CALLIGRAPHY_TEST_DATA_DIR);
  // The 58 embedded characters.
  const auto embedded_labels =
      cli::parse_cnchar_orders(read_text(data / "cnchar_sample_labels.json"), "cnchar_sample_labels.json");
  const auto embedded = cli::validate_against_cnchar(CharacterLibrary::embedded(), embedded_labels, {}, 1);
  CHECK(embedded.compared == embedded_labels.size());
  CHECK(embedded.strokes >= 250);
  CHECK(embedded.agreement() >= 0.96);
  // 121 real characters (every 56th of those both sources cover), copied verbatim from the full data.
  const auto sample_labels = cli::parse_cnchar_orders(read_text(data / "cnchar_sample_large_labels.json"),
                                                      "cnchar_sample_large_labels.json");
  const auto sample_library = CharacterLibrary::from_directory(data / "hanzi-writer-sample");
  const auto sample = cli::validate_against_cnchar(sample_library, sample_labels, {}, 2);
  CHECK(sample.compared == 121);
  CHECK(sample.count_mismatch.empty());
  CHECK(sample.strokes >= 1300);
  CHECK(sample.agreement() >= 0.965);  // measured 97.2 %; the whole corpus gives 97.15 %
  // Deterministic whatever the thread count.
  CHECK(cli::validate_against_cnchar(sample_library, sample_labels, {}, 1).agreeing == sample.agreeing);
  // The report names the figures.
  const std::string md = cli::cnchar_validation_markdown(sample, "sample", "sample labels");
  CHECK(md.find("Per-stroke agreement") != std::string::npos);
  CHECK(count(md, "\n| ") >= 39 + 20);
}

TEST_CASE("classify_pieces recognises canonical pieces and rejects an empty stroke", "[classify]") {
  const auto piece = [](double start, double end, double length) {
    StrokePiece p;
    p.start_direction_deg = start;
    p.end_direction_deg = end;
    p.length = length;
    return p;
  };
  CHECK(classify_pieces(std::vector{piece(8, 5, 500)}) == typical("H"));
  CHECK(classify_pieces(std::vector{piece(-88, -95, 600)}) == typical("S"));
  CHECK(classify_pieces(std::vector{piece(-40, -48, 120)}) == typical("D"));
  CHECK(classify_pieces(std::vector{piece(10, 10, 400), piece(-100, -100, 400)}) == typical("HZ"));
  CHECK(classify_pieces(std::vector{piece(10, 10, 400), piece(-95, -95, 500), piece(150, 150, 120)}) ==
        typical("HZG"));
  CHECK(classify_pieces(std::vector{piece(-90, -90, 500), piece(30, 30, 150)}) == typical("ST"));
  // A short down-right first piece is the brush's entry, not part of the shape: still a 撇.
  CHECK(classify_pieces(std::vector{piece(-45, -45, 50), piece(-125, -140, 400)}) == typical("P"));
  CHECK_THROWS_AS(classify_pieces(std::vector<StrokePiece>{}), InvalidArgument);
}

TEST_CASE("classify_pieces: the end's turn settles 左点 vs 竖, 点 vs 竖, 横 vs 提, 横 vs flat 捺",
          "[classify]") {
  const auto piece = [](double start, double end, double length, double exit_turn) {
    StrokePiece p;
    p.start_direction_deg = start;
    p.end_direction_deg = end;
    p.length = length;
    p.exit_turn_deg = exit_turn;
    return std::vector{p};
  };
  CHECK(classify_pieces(piece(-95, -105, 180, 12)) == typical("D2"));  // curls back: 冖's left dot
  CHECK(classify_pieces(piece(-95, -105, 180, -3)) == typical("S"));   // no curl: 艹's short vertical
  CHECK(classify_pieces(piece(5, 20, 300, 0)) == typical("T"));        // straight flick
  CHECK(classify_pieces(piece(5, 20, 300, -15)) == typical("H"));      // the 横's press at its end
  CHECK(classify_pieces(piece(-3, -3, 800, 15)) == typical("TN"));     // flat 捺: the end turns up
  CHECK(classify_pieces(piece(-3, -3, 800, -15)) == typical("H"));
  CHECK(classify_pieces(piece(-55, -77, 180, 0)) == typical("S"));    // small 口's left side
  CHECK(classify_pieces(piece(-55, -77, 180, -15)) == typical("D"));  // a 点's end turns clockwise
}

TEST_CASE("Fitting: brush entry and exit hooks are trimmed", "[fitting]") {
  // A horizontal with a 20-unit entry hook from above-left and a 20-unit exit flick downwards.
  const std::vector<Vec2> median = {{100, 520}, {115, 505}, {300, 510}, {600, 515}, {800, 520}, {812, 504}};
  const FittedStroke f = fit_stroke(median);
  CHECK(f.stroke.typical_id == typical("H"));
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK(f.stroke.elements[0].kind == ElementKind::line);
  CHECK(f.stroke.feature_point(0).isApprox(Vec2(115, 505)));
  CHECK(f.stroke.feature_point(1).isApprox(Vec2(800, 520)));
  CHECK(f.stroke.median.size() == median.size());  // the source median is kept whole
}

TEST_CASE("Fitting: a corner rounded over several vertices is one feature point", "[fitting]") {
  // 横折: the turn from right to down is spread over three vertices 20-30 units apart.
  const std::vector<Vec2> median = {{100, 700}, {400, 705}, {600, 710}, {630, 700},
                                    {648, 680}, {655, 650}, {655, 400}, {655, 150}};
  const FittedStroke f = fit_stroke(median);
  REQUIRE(f.pieces.size() == 2);
  CHECK(f.stroke.typical_id == typical("HZ"));
  const Vec2 corner = f.stroke.feature_point(f.pieces[1].first_element);
  CHECK((corner - Vec2(655, 712)).norm() < 25.0);  // near where the two straight parts meet
  CHECK(f.stroke.attraction_factors[f.pieces[1].first_element] ==
        typical_stroke(typical("HZ")).corner_attraction);
  CHECK(f.stroke.attraction_factors.front() == typical_stroke(typical("HZ")).default_attraction);
}

TEST_CASE("Fitting: a vertical and its hook joined by one long segment keep both corners", "[fitting]") {
  // 横折钩 as in 丹 2: rounded corner, one 600-unit segment, then the hook's own bend.
  const std::vector<Vec2> median = {{300, 700}, {500, 730}, {530, 715}, {545, 690},
                                    {545, 90},  {535, 70},  {515, 60},  {420, 110}};
  const FittedStroke f = fit_stroke(median);
  CHECK(f.pieces.size() == 3);
  CHECK(f.stroke.typical_id == typical("HZG"));
}

TEST_CASE("Fitting: a zig-zag noisy median stays one straight element", "[fitting]") {
  std::vector<Vec2> median;
  for (int i = 0; i <= 30; ++i) median.emplace_back(100.0 + 20.0 * i, 500.0 + (i % 2 ? 4.0 : -4.0));
  const FittedStroke f = fit_stroke(median);
  CHECK(f.pieces.size() == 1);
  CHECK(f.stroke.elements.size() == 1);
  CHECK(f.stroke.typical_id == typical("H"));
  CHECK(f.max_deviation <= FitOptions{}.tolerance);
}

TEST_CASE("Fitting: two-point medians and tiny strokes", "[fitting]") {
  const std::vector<Vec2> two = {{500, 800}, {500, 200}};
  FittedStroke f = fit_stroke(two);
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK(f.stroke.elements[0].kind == ElementKind::line);
  CHECK(f.stroke.typical_id == typical("S"));
  CHECK(f.max_deviation == Approx(0.0).margin(1e-9));

  const std::vector<Vec2> tiny = {{400, 400}, {405, 396}, {409, 392}};  // 9 units, like 瀝 stroke 5
  f = fit_stroke(tiny);
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK((f.stroke.elements[0].end() - f.stroke.elements[0].start()).norm() > 0.0);
  CHECK(f.stroke.typical_id == typical("D"));
  CHECK(std::isfinite(f.max_deviation));

  const std::vector<Vec2> repeated = {{300, 300}, {300, 300}};  // a point written twice: rule (d)
  f = fit_stroke(repeated);
  REQUIRE(f.stroke.elements.size() == 1);
  CHECK(f.stroke.elements[0].start() == f.stroke.elements[0].end());
}

namespace {

// A minimal XML well-formedness check: tags nest and close, attributes' quotes pair up.
bool well_formed_xml(const std::string& xml) {
  std::vector<std::string> open;
  std::size_t i = 0;
  while ((i = xml.find('<', i)) != std::string::npos) {
    const std::size_t end = xml.find('>', i);
    if (end == std::string::npos) return false;
    const std::string tag = xml.substr(i + 1, end - i - 1);
    i = end + 1;
    if (tag.empty()) return false;
    if (count(tag, "\"") % 2 != 0) return false;
    if (tag[0] == '?' || tag[0] == '!') continue;
    if (tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1)) return false;
      open.pop_back();
      continue;
    }
    if (tag.back() == '/') continue;
    open.push_back(tag.substr(0, tag.find_first_of(" \n")));
  }
  return open.empty();
}

}  // namespace

TEST_CASE("Model SVG (paper Fig. 13): well-formed, one path per element, one red dot per feature point",
          "[strokes]") {
  const auto library = CharacterLibrary::embedded();
  for (char32_t cp : {U'永', U'我', U'鼎'}) {
    const Character c = library.load(cp);
    const std::string svg = model_svg(c);
    CHECK(well_formed_xml(svg));
    std::size_t elements = 0;
    std::size_t features = 0;
    std::size_t inner_controls = 0;
    for (const auto& s : c.strokes) {
      elements += s.elements.size();
      features += s.feature_point_count();
      for (const auto& e : s.elements) inner_controls += static_cast<std::size_t>(e.degree - 1);
    }
    CHECK(count(svg, "class=\"element\"") == elements);
    CHECK(count(svg, "class=\"feature-point\"") == features);
    CHECK(count(svg, "class=\"control-point\"") == inner_controls);
    CHECK(count(svg, "class=\"stroke-number\"") == c.strokes.size());
  }
  CHECK_FALSE(well_formed_xml("<svg><g></svg>"));  // the checker itself can fail
}
