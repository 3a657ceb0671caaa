// Stroke outlines for drawing: SVG path data (M, L, Q, C, Z) to polygons, flattened within the
// tolerance; hanzi-writer-data's `strokes` loaded in stroke order; bad paths refused by position.
#include "calligraphy/model/stroke_outline.hpp"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "model/outline_json_reader.hpp"

using namespace calligraphy;

namespace {

// Distance from p to the quadratic Bezier (p0, c, p1): dense sampling, then a ternary search around the
// best sample (the distance is unimodal that close to the curve).
double distance_to_quadratic(const Vec2& p, const Vec2& p0, const Vec2& c, const Vec2& p1) {
  const auto at = [&](double t) {
    return (p - ((1 - t) * (1 - t) * p0 + 2 * t * (1 - t) * c + t * t * p1)).norm();
  };
  constexpr int kSamples = 2000;
  int best = 0;
  for (int i = 1; i <= kSamples; ++i) {
    if (at(i / double(kSamples)) < at(best / double(kSamples))) best = i;
  }
  double lo = std::max(0, best - 1) / double(kSamples);
  double hi = std::min(kSamples, best + 1) / double(kSamples);
  for (int k = 0; k < 200; ++k) {
    const double a = lo + (hi - lo) / 3;
    const double b = hi - (hi - lo) / 3;
    if (at(a) < at(b)) {
      hi = b;
    } else {
      lo = a;
    }
  }
  return at(0.5 * (lo + hi));
}

}  // namespace

TEST_CASE("Straight SVG subpaths become closed polygons, absolute or relative", "[outline]") {
  const auto square = parse_svg_path("M 0 0 L 10 0 L 10 10 L 0 10 Z");
  REQUIRE(square.size() == 1);
  CHECK(square[0].size() == 4);
  CHECK(square[0][2] == Vec2(10, 10));
  const auto relative = parse_svg_path("m0,0 l10,0 0,10 -10,0z M 20 20 30 20 30 30 Z");
  REQUIRE(relative.size() == 2);
  CHECK(relative[0] == square[0]);  // implicit lineto after l repeats the command
  CHECK(relative[1].size() == 3);   // implicit lineto after M
  CHECK(polygon_contains(square[0], Vec2(5, 5)));
  CHECK_FALSE(polygon_contains(square[0], Vec2(15, 5)));
  CHECK_FALSE(polygon_contains(square[0], Vec2(5, -1)));
}

TEST_CASE("Curves are flattened within the tolerance", "[outline]") {
  const Vec2 p0(0, 0), c(50, 100), p1(100, 0);
  for (const double tolerance : {4.0, 1.0, 0.1}) {
    const auto polygons = parse_svg_path("M 0 0 Q 50 100 100 0 Z", tolerance);
    REQUIRE(polygons.size() == 1);
    const OutlinePolygon& curve = polygons[0];
    double worst = 0.0;
    for (std::size_t i = 0; i < curve.size(); ++i) {
      CHECK(distance_to_quadratic(curve[i], p0, c, p1) < 1e-9);  // vertices lie on the curve
      if (i + 1 < curve.size()) {  // the chord's midpoint stays within the tolerance
        worst = std::max(worst, distance_to_quadratic(0.5 * (curve[i] + curve[i + 1]), p0, c, p1));
      }
    }
    INFO("tolerance " << tolerance << ", " << curve.size() << " vertices");
    CHECK(worst <= tolerance);
    CHECK(worst > tolerance / 16);  // not far finer than asked
  }
  const auto cubic = parse_svg_path("M 0 0 C 0 100 100 100 100 0 Z", 0.5);
  REQUIRE(cubic.size() == 1);
  CHECK(cubic[0].size() > 8);
  CHECK(cubic[0].back() == Vec2(100, 0));
}

TEST_CASE("Bad SVG path data is refused with its position", "[outline]") {
  CHECK_THROWS_WITH(parse_svg_path("M 0 0 A 5 5 0 0 1 10 10 Z"),
                    Catch::Contains("byte 6") && Catch::Contains("unsupported path command 'A'"));
  CHECK_THROWS_WITH(parse_svg_path("M 0 0 L 10"), Catch::Contains("expected a number"));
  CHECK_THROWS_WITH(parse_svg_path("L 0 0 L 1 1 L 2 0 Z"), Catch::Contains("before the first M"));
  CHECK_THROWS_WITH(parse_svg_path("M 0 0 L x 1 Z"), Catch::Contains("expected a number, got 'x"));
  CHECK_THROWS_WITH(parse_svg_path("M 0 0 L 1e9 1 L 2 2 Z"), Catch::Contains("outside"));
  CHECK_THROWS_WITH(parse_svg_path("M 0 0 L 1 1 Z"), Catch::Contains("fewer than 3"));
  CHECK_THROWS_WITH(parse_svg_path("7 7"), Catch::Contains("expected a command"));
  CHECK_THROWS_AS(parse_svg_path("M 0 0 L 1 0 L 1 1 Z", 0.0), InvalidArgument);
  std::string many = "M 0 0";
  for (int i = 0; i < 1000; ++i) many += " Q 0 1e5 " + std::to_string(i % 2 ? 100000 : -100000) + " 0";
  CHECK_THROWS_WITH(parse_svg_path(many + " Z", 1e-6), Catch::Contains("vertices after flattening"));
}

TEST_CASE("hanzi-writer-data outlines load in stroke order and enclose their medians", "[outline]") {
  const CharacterLibrary library = CharacterLibrary::embedded();
  for (const char32_t c : {U'永', U'十', U'我', U'鼎'}) {
    const CharacterOutlines outlines = library.load_outlines(c);
    const CharacterData data = library.load_data(c);
    REQUIRE(outlines.strokes.size() == data.medians.size());
    for (std::size_t s = 0; s < data.medians.size(); ++s) {
      REQUIRE_FALSE(outlines.strokes[s].empty());
      // The median's middle point lies inside its own stroke's outline.
      const std::vector<Vec2>& median = data.medians[s];
      const Vec2 middle = 0.5 * (median[median.size() / 2] + median[(median.size() - 1) / 2]);
      bool inside = false;
      for (const OutlinePolygon& polygon : outlines.strokes[s])
        inside = inside || polygon_contains(polygon, middle);
      INFO("stroke " << s + 1);
      CHECK(inside);
    }
  }
}

TEST_CASE("Character files without usable outlines are refused by JSON pointer", "[outline]") {
  const std::string folder = std::string(CALLIGRAPHY_TEST_DATA_DIR) + "/hanzi-writer-sample";
  CHECK(CharacterLibrary::from_directory(folder).load_outlines(U'一').strokes.size() == 1);
  CHECK_THROWS_AS(CharacterLibrary::embedded().load_outlines(U'一'), CharacterNotFound);
  CHECK_THROWS_AS(CharacterLibrary::embedded().load_outlines(U'永', -1.0), InvalidArgument);
}

TEST_CASE("The outline reader takes only a non-empty array of strings under strokes", "[outline]") {
  using detail::read_outlines_json;
  const auto ok =
      read_outlines_json(R"({"medians": [[[0, 0], [1, 1]]], "strokes": ["M 0 0 L 1 0 L 1 1 Z"]})");
  REQUIRE(ok.ok);
  CHECK(ok.paths.size() == 1);
  const auto missing = read_outlines_json(R"({"medians": []})");
  CHECK_FALSE(missing.ok);
  CHECK(missing.where == "/strokes");
  const auto number = read_outlines_json(R"({"strokes": ["M 0 0 L 1 0 L 1 1 Z", 5]})");
  CHECK(number.where == "/strokes/1");
  CHECK(number.what == "expected an SVG path, got a number");
  CHECK(read_outlines_json(R"({"strokes": []})").what == "expected a non-empty array of SVG paths");
  CHECK(read_outlines_json(R"({"strokes": {"a": 1}})").where == "/strokes");
  CHECK(read_outlines_json(R"([1, 2])").where == "/");
  CHECK(read_outlines_json(R"({"strokes": ["M 0 0 L 1 0 L 1 1 Z"], "strokes": ["x"]})").what ==
        "duplicate key");
  CHECK(read_outlines_json(R"({"x": )" + std::string(100, '[')).what.find("nested deeper") !=
        std::string::npos);
  CHECK(read_outlines_json(R"({"strokes": ["M 0 0")").what == "malformed JSON");
}

TEST_CASE("Open SVG polylines: a pen's line, with S reflecting the previous control point", "[outline]") {
  // KanjiVG writes its centre lines with c and s: the s's first control point is the c's second reflected.
  const auto lines = parse_svg_polylines("M0,0 c0,10 10,10 10,0 s10,-10 10,0", 0.01);
  REQUIRE(lines.size() == 1);
  const std::vector<Vec2>& line = lines.front();
  CHECK(line.front().isApprox(Vec2(0, 0)));
  CHECK(line.back().isApprox(Vec2(20, 0)));
  // The first arch rises to y = 7.5 at its middle, the second, its mirror image, falls to -7.5.
  double top = 0.0;
  double bottom = 0.0;
  for (const Vec2& p : line) {
    top = std::max(top, p.y());
    bottom = std::min(bottom, p.y());
  }
  CHECK(top == Approx(7.5).margin(0.02));
  CHECK(bottom == Approx(-7.5).margin(0.02));
  // Two points make an open line (an outline needs three); one is refused.
  CHECK(parse_svg_polylines("M1,2 L3,4").front().size() == 2);
  CHECK_THROWS_AS(parse_svg_polylines("M1,2"), DataError);
}
