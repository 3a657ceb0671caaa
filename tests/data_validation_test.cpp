// Character data refused at the door, and fitting work bounded by the number of points: hostile files
// (tests/data/hostile) and generated inputs must give a DataError naming the file, the character and
// the position, never a crash, a hang or a silently wrong model.
#include <sys/stat.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/element.hpp"
#include "calligraphy/model/fitting.hpp"
#include "model/corner_search.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;
using calligraphy::testing::sanitizer_subset;

namespace {

const std::filesystem::path kHostile = std::filesystem::path(CALLIGRAPHY_TEST_DATA_DIR) / "hostile";

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The DataError message of parsing `json` as character 一 from `source`; empty when it parses.
std::string refusal(const std::string& json, const std::string& source = "doc.json") {
  try {
    (void)parse_hanzi_writer_json(json, U'一', source);
  } catch (const DataError& e) {
    return e.what();
  }
  return {};
}

std::string hostile_refusal(const std::string& name) {
  const auto path = kHostile / name;
  INFO(name);
  REQUIRE(std::filesystem::is_regular_file(path));
  return refusal(read_text(path), path.string());
}

std::filesystem::path validation_scratch_folder(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("calligraphy-validation-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string points_json(std::size_t count, double x0, double dx) {
  std::string out = "[";
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) out += ",";
    out += '[';
    out += std::to_string(x0 + dx * static_cast<double>(i));
    out += ',';
    out += std::to_string(i % 2);
    out += ']';
  }
  return out + "]";
}

std::string medians_json(const std::vector<std::string>& medians) {
  std::string out = "{\"medians\": [";
  for (std::size_t i = 0; i < medians.size(); ++i) out += (i > 0 ? "," : "") + medians[i];
  return out + "]}";
}

bool all_control_points_finite(const Stroke& stroke) {
  for (const StrokeElement& e : stroke.elements) {
    for (int i = 0; i <= e.degree; ++i) {
      if (!e.control[static_cast<std::size_t>(i)].allFinite()) return false;
    }
  }
  return true;
}

// Consecutive elements join (the end of one is the start of the next, within rounding: a piece's last
// sample may stand a rounding error short of its corner), the first starts and the last ends at the
// median's ends.
bool elements_chain_along(const Stroke& stroke, const Vec2& first, const Vec2& last) {
  const auto same = [](const Vec2& a, const Vec2& b) { return (a - b).norm() <= 1e-12 * (1.0 + a.norm()); };
  if (stroke.elements.empty() || !same(stroke.elements.front().start(), first) ||
      !same(stroke.elements.back().end(), last)) {
    return false;
  }
  for (std::size_t k = 1; k < stroke.elements.size(); ++k) {
    if (!same(stroke.elements[k].start(), stroke.elements[k - 1].end())) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("Hostile character files are refused naming the file, the character and the JSON pointer",
          "[validation]") {
  struct Case {
    const char* file;
    const char* where;
    const char* why;
  };
  const Case cases[] = {
      {"far_coordinates_1e17.json", "/medians/0/1/0", "outside"},
      {"huge_coordinate_1e308.json", "/medians/0/1/0", "outside"},
      {"huge_integer_1.8e19.json", "/medians/0/1/0", "outside"},
      {"number_out_of_range_1e400.json", "/medians/0/1/0", "out of range"},
      {"one_point_median.json", "/medians/1", "at least 2 distinct points"},
      {"equal_points_median.json", "/medians/0", "at least 2 distinct points"},
      {"empty_median.json", "/medians/0", "at least 2 distinct points"},
      {"no_medians.json", "/medians", "non-empty"},
      {"string_coordinate.json", "/medians/0/1/1", "expected a number, got a string"},
      {"three_coordinates.json", "/medians/0/0/2", "two numbers"},
      {"null_point.json", "/medians/0/1", "got null"},
      {"duplicate_medians_key.json", "/medians", "duplicate"},
      {"not_an_object.json", "/", "expected a JSON object"},
      {"truncated.json", "line:column 2:1", "malformed JSON"},
      {"deep_medians.json", "/medians/0/0/0", "expected a number, got an array"},
      {"deep_in_skipped_key.json", "/strokes/0/0/0", "nested deeper than 16 levels"},
  };
  for (const Case& c : cases) {
    INFO(c.file);
    const std::string message = hostile_refusal(c.file);
    CHECK_THAT(message, Catch::Contains(c.file) && Catch::Contains("U+4E00") && Catch::Contains(c.where) &&
                            Catch::Contains(c.why));
  }
}

TEST_CASE("Nesting 100,000 deep is refused at the nesting bound without recursion", "[validation]") {
  const std::size_t depth = 100'000;
  const std::string in_medians = "{\"medians\": " + std::string(depth, '[') + std::string(depth, ']') + "}";
  CHECK_THAT(refusal(in_medians), Catch::Contains("/medians/0/0/0") && Catch::Contains("got an array"));
  const std::string in_skipped_key = "{\"radStrokes\": " + std::string(depth, '[') + std::string(depth, ']') +
                                     ", \"medians\": [[[0,0],[1,1]]]}";
  const std::string message = refusal(in_skipped_key);
  CHECK_THAT(message, Catch::Contains("nested deeper than " + std::to_string(kMaxJsonDepth)));
  // The pointer names the first level too deep, so the message stays short whatever the input's depth.
  CHECK(message.size() < 200);
  std::string nested_objects;
  for (std::size_t i = 0; i < 1000; ++i) nested_objects += "{\"a\":";
  nested_objects += "1" + std::string(1000, '}');
  CHECK_THAT(refusal(nested_objects), Catch::Contains("nested deeper than"));
}

TEST_CASE("The bounds of character data are inclusive, one past them is refused", "[validation]") {
  const double edge = kMaxDataCoordinate;
  const auto at = [](double x, double y) {
    std::ostringstream out;
    out.precision(17);
    out << "[" << x << "," << y << "]";
    return out.str();
  };
  const std::string inside = "[" + at(-edge, -edge) + "," + at(edge, -edge) + "," + at(edge, edge) + "]";
  const CharacterData data = parse_hanzi_writer_json(medians_json({inside}), U'一', "edge.json");
  REQUIRE(data.medians.size() == 1);
  CHECK(data.medians[0][2] == Vec2(edge, edge));
  CHECK_THAT(refusal(medians_json({"[" + at(0, 0) + "," + at(0, edge + 0.5) + "]"})),
             Catch::Contains("/medians/0/1/1") && Catch::Contains("outside"));
  CHECK_THAT(refusal(medians_json({"[" + at(0, 0) + "," + at(-edge - 0.5, 0) + "]"})),
             Catch::Contains("/medians/0/1/0"));

  std::vector<std::string> strokes(kMaxCharacterStrokes, "[[0,0],[1,1]]");
  CHECK(parse_hanzi_writer_json(medians_json(strokes), U'一', "many.json").medians.size() ==
        kMaxCharacterStrokes);
  strokes.push_back("[[0,0],[1,1]]");
  CHECK_THAT(
      refusal(medians_json(strokes)),
      Catch::Contains("/medians/" + std::to_string(kMaxCharacterStrokes)) && Catch::Contains("more than"));

  const std::string longest = points_json(kMaxMedianPoints, 0.0, 1.0);
  CHECK(parse_hanzi_writer_json(medians_json({longest}), U'一', "long.json").medians[0].size() ==
        kMaxMedianPoints);
  CHECK_THAT(
      refusal(medians_json({points_json(kMaxMedianPoints + 1, 0.0, 1.0)})),
      Catch::Contains("/medians/0/" + std::to_string(kMaxMedianPoints)) && Catch::Contains("more than"));
  // Per median within bounds, too many in all: refused at the first point beyond the total.
  static_assert(kMaxCharacterPoints >= kMaxMedianPoints && kMaxCharacterPoints < 3 * kMaxMedianPoints);
  CHECK_THAT(refusal(medians_json({longest, longest, longest})),
             Catch::Contains("/medians/2/" + std::to_string(kMaxCharacterPoints - 2 * kMaxMedianPoints)) &&
                 Catch::Contains("in all medians"));

  const std::string oversized(kMaxCharacterFileBytes + 1, ' ');
  CHECK_THAT(refusal(oversized), Catch::Contains(std::to_string(kMaxCharacterFileBytes + 1) + " bytes"));
}

TEST_CASE("A folder refuses files that are not regular or too large, without blocking", "[validation]") {
  const auto dir = validation_scratch_folder("files");
  const auto library = CharacterLibrary::from_directory(dir);
  const auto fifo = dir / "一.json";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // Opening a FIFO for reading blocks until a writer comes: this would hang without the check.
  CHECK_THROWS_AS(library.load_data(U'一'), DataError);
  CHECK_THROWS_WITH(library.load_data(U'一'), Catch::Contains(fifo.string()) && Catch::Contains("FIFO"));

  std::filesystem::create_directory(dir / "二.json");
  CHECK_THROWS_WITH(library.load_data(U'二'), Catch::Contains("二.json") && Catch::Contains("directory"));

  // A device never ends: reading /dev/zero would exhaust memory without the check.
  std::error_code ec;
  std::filesystem::create_symlink("/dev/zero", dir / "三.json", ec);
  if (!ec)
    CHECK_THROWS_WITH(library.load_data(U'三'), Catch::Contains("三.json") && Catch::Contains("device"));

  const auto big = dir / "四.json";
  std::ofstream(big) << "{}";
  std::filesystem::resize_file(big, kMaxCharacterFileBytes + 1);  // sparse: costs no disk
  CHECK_THROWS_WITH(
      library.load_data(U'四'),
      Catch::Contains("四.json") && Catch::Contains(std::to_string(kMaxCharacterFileBytes + 1)));

  std::filesystem::copy_file(std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "data/hanzi-writer-data/永.json",
                             dir / "永.json");
  CHECK(library.load_data(U'永').medians == CharacterLibrary::embedded().load_data(U'永').medians);
  CHECK_THROWS_AS(library.load_data(U'五'), CharacterNotFound);
  std::filesystem::remove_all(dir);
}

TEST_CASE("A rejection through the folder names the file and 1e400 is a DataError, not an internal error",
          "[validation]") {
  const auto dir = validation_scratch_folder("named");
  std::filesystem::copy_file(kHostile / "number_out_of_range_1e400.json", dir / "一.json");
  const auto library = CharacterLibrary::from_directory(dir);
  CHECK_THROWS_AS(library.load(U'一'), DataError);
  CHECK_THROWS_WITH(library.load(U'一'), Catch::Contains((dir / "一.json").string()) &&
                                             Catch::Contains("/medians/0/1/0") && Catch::Contains("1e400"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("A folder without character files is an error naming the folder", "[validation]") {
  const auto dir = validation_scratch_folder("empty");
  CHECK_THROWS_AS(CharacterLibrary::from_directory(dir).characters(), DataError);
  CHECK_THROWS_WITH(CharacterLibrary::from_directory(dir).characters(), Catch::Contains(dir.string()));
  std::ofstream(dir / "package.json") << "{}";  // not a character file
  CHECK_THROWS_WITH(CharacterLibrary::from_directory(dir).characters(),
                    Catch::Contains("no character files"));
  std::ofstream(dir / "永.json") << "{}";
  CHECK(CharacterLibrary::from_directory(dir).characters() == std::vector<char32_t>{U'永'});
  std::filesystem::remove_all(dir);
}

TEST_CASE("A file with outlines has one per median, and a name of white space or a control is no character's",
          "[validation]") {
  const std::string two = R"([[[0,0],[9,9]],[[0,9],[9,0]]])";
  CHECK(parse_hanzi_writer_json(R"({"strokes":["M 0 0 Z","M 1 1 Z"],"medians":)" + two + "}", U'一', "a.json")
            .medians.size() == 2);
  CHECK(parse_hanzi_writer_json(R"({"medians":)" + two + "}", U'一', "b.json").medians.size() == 2);
  CHECK_THAT(refusal(R"({"strokes":["M 0 0 Z"],"medians":)" + two + "}"),
             Catch::Contains("/strokes") && Catch::Contains("1 stroke outlines for 2 medians"));
  CHECK_THAT(refusal(R"({"medians":)" + two + R"(,"strokes":["M 0 0 Z","M 1 1 Z","M 2 2 Z"]})"),
             Catch::Contains("3 stroke outlines for 2 medians"));
  // An outline path as long as a store keeps as text (1,048,575 bytes) is read; one byte more is refused at
  // its pointer, so that corpus build lists the file instead of failing to write the whole store.
  const std::string at_bound = "M 0 0 Z" + std::string(1'048'575 - 7, ' ');
  CHECK(parse_hanzi_writer_json(R"({"strokes":["M 0 0 Z",")" + at_bound + R"("],"medians":)" + two + "}",
                                U'一', "c.json")
            .medians.size() == 2);
  CHECK_THAT(refusal(R"({"strokes":["M 0 0 Z",")" + at_bound + R"( "],"medians":)" + two + "}"),
             Catch::Contains("/strokes/1") && Catch::Contains("outline path of 1048576 bytes"));

  const auto dir = validation_scratch_folder("names");
  for (const char* name : {"永.json", " .json", "\x1b.json", "\t.json", "\u3000.json", "\u00a0.json"})
    std::ofstream(dir / name) << "{}";
  const auto library = CharacterLibrary::from_directory(dir);
  CHECK(library.characters() == std::vector<char32_t>{U'永'});
  CHECK(library.contains(U'永'));
  CHECK_FALSE(library.contains(U' '));
  CHECK_FALSE(library.contains(U'\x1b'));
  CHECK_FALSE(library.contains(U'\u3000'));
  std::filesystem::remove_all(dir);
}

TEST_CASE("Far coordinates fit with corner-search work bounded by the number of points", "[validation]") {
  // The corner search used to step its window by 4 units from 0 to the arc length: 1e17 never
  // advanced (4 is below the rounding of 1e17) and 1e9 took seconds.
  for (const double far : {1e5, 1e9, 1e17, 1e149}) {
    INFO(far);
    const std::vector<Vec2> median{Vec2(0, 0), Vec2(far, 0), Vec2(far, far)};
    std::vector<Vec2> pts = median;
    detail::CornerSearchWork work;
    const auto corners = detail::find_corners(pts, FitOptions{}, &work);
    CHECK(corners == std::vector<std::size_t>{1});
    CHECK(work.centres <= detail::kMaxCornerCentresPerPoint * median.size());
    const FittedStroke fitted = fit_stroke(median);
    REQUIRE(fitted.stroke.elements.size() == 2);  // a right angle: two LSEs meeting at the corner
    CHECK(fitted.stroke.elements[0].end() == median[1]);
    CHECK(elements_chain_along(fitted.stroke, median.front(), median.back()));
  }
  CHECK_THROWS_AS(fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(1e151, 0)}), InvalidArgument);
  CHECK_THROWS_WITH(fit_stroke(std::vector<Vec2>{Vec2(0, 0), Vec2(0, -1e300)}), Catch::Contains("point 1"));
}

namespace {

// A 10,000-point median (kMaxMedianPoints) of alternating bends of 40 and 120 degrees with segments longer
// than the corner window (so each window holds one vertex): a corner every second point, each piece a bent
// 3-point polyline that no Bezier fits, the costliest shape for the fitter found so far.
void check_fit_work_bounded(double segment) {
  const double pi = std::acos(-1.0);
  // The sanitizer builds fit a quarter of the points: the bound is per point, and the fit of the whole
  // 10,000 took 28 s there (the Release build fits all of them).
  const std::size_t points = calligraphy::testing::full_sweeps() ? kMaxMedianPoints : kMaxMedianPoints / 4;
  std::vector<Vec2> median;
  Vec2 p(-kMaxDataCoordinate / 2, -kMaxDataCoordinate / 2);
  double direction = 0.0;
  for (std::size_t i = 0; i < points; ++i) {
    median.push_back(p);
    direction += (i % 2 == 0 ? 40.0 : 120.0) * pi / 180.0;
    p += segment * Vec2(std::cos(direction), std::sin(direction));
  }
  std::vector<Vec2> pts = median;
  detail::CornerSearchWork work;
  (void)detail::find_corners(pts, FitOptions{}, &work);
  CHECK(work.centres <= detail::kMaxCornerCentresPerPoint * median.size());
  CHECK(work.summed <= detail::kMaxCornerCentresPerPoint * median.size());
  const auto start = std::chrono::steady_clock::now();
  const FittedStroke fitted = fit_stroke(median);
  WARN("fit of " << median.size() << " points, segments " << segment << ": "
                 << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s, "
                 << fitted.stroke.elements.size() << " elements");
  CHECK(fitted.pieces.size() > median.size() / 4);
  CHECK(all_control_points_finite(fitted.stroke));
  CHECK(elements_chain_along(fitted.stroke, median.front(), median.back()));
  CHECK(std::isfinite(fitted.max_deviation));
}

}  // namespace

// Two test cases (segments of 100 and 1000 units), so that CTest runs them side by side.
TEST_CASE("A 10,000-point median of short segments fits with work bounded by its points", "[validation]") {
  check_fit_work_bounded(100.0);
}

TEST_CASE("A 10,000-point median of long segments fits with work bounded by its points", "[validation]") {
  check_fit_work_bounded(1000.0);
}

TEST_CASE("StrokeElement refuses non-finite control points, naming the point", "[validation]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(StrokeElement::line(Vec2(nan, 0), Vec2(1, 1)),
                    "StrokeElement::line: control point 0 is not finite");
  CHECK_THROWS_WITH(StrokeElement::line(Vec2(0, 0), Vec2(1, -inf)),
                    "StrokeElement::line: control point 1 is not finite");
  const Vec2 points[4] = {Vec2(0, 0), Vec2(1, 1), Vec2(2, 0), Vec2(3, nan)};
  CHECK_THROWS_AS(StrokeElement::bezier(points, 4), InvalidArgument);
  CHECK_THROWS_WITH(StrokeElement::bezier(points, 4), "StrokeElement::bezier: control point 3 is not finite");
  CHECK_NOTHROW(StrokeElement::bezier(points, 3));
  CHECK(StrokeElement::line(Vec2(1, 2), Vec2(1, 2)).point(0.5) ==
        Vec2(1, 2));  // rule (d): zero length is fine
}

TEST_CASE("The Table-3 view refuses an element whose degree its control points cannot hold", "[validation]") {
  Character character;
  Stroke stroke;
  stroke.elements.push_back(StrokeElement::line(Vec2(0, 0), Vec2(1, 0)));
  StrokeElement bad = StrokeElement::line(Vec2(1, 0), Vec2(2, 0));
  bad.degree = kMaxElementDegree + 1;
  stroke.elements.push_back(bad);
  character.strokes.push_back(stroke);
  CHECK_THROWS_AS(character_table(character), InvalidArgument);
  CHECK_THROWS_WITH(character_table(character),
                    Catch::Contains("stroke 1 element 2") && Catch::Contains("degree 5"));
  character.strokes[0].elements[1].degree = 0;
  CHECK_THROWS_WITH(character_table(character), Catch::Contains("degree 0"));
}

TEST_CASE("Past its scan budget the stroke deviation is an upper bound of the exact one", "[validation]") {
  // An 18-vertex star walked round and round: the points' nearest segments tie within rounding over
  // every lap, which made the exact scan quadratic in the points.
  const double pi = std::acos(-1.0);
  std::vector<Vec2> median;
  Vec2 p(0, 0);
  double direction = 0.0;
  for (std::size_t i = 0; i < 2000; ++i) {
    median.push_back(p);
    direction += (i % 2 == 0 ? 40.0 : 120.0) * pi / 180.0;
    p += 100.0 * Vec2(std::cos(direction), std::sin(direction));
  }
  const FittedStroke fitted = fit_stroke(median);
  std::vector<Vec2> curve;
  for (const StrokeElement& e : fitted.stroke.elements) {
    for (int i = 0; i <= 64; ++i) curve.push_back(e.point(i / 64.0));
  }
  // The bound holds for every point of the median: each point's brute-force distance to the sampled curve
  // is checked (under the sanitizers a random 200 of the 2000 points, tests/test_sizing.hpp).
  for (const Vec2& q : sanitizer_subset(median, 200, "median points")) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i < curve.size(); ++i) {
      const Vec2 d = curve[i] - curve[i - 1];
      if (d.squaredNorm() == 0.0) continue;  // the joint between two elements
      const double t = std::clamp((q - curve[i - 1]).dot(d) / d.squaredNorm(), 0.0, 1.0);
      nearest = std::min(nearest, (curve[i - 1] + t * d - q).norm());
    }
    INFO("point (" << q.x() << ", " << q.y() << ") is " << nearest << " from the fitted elements");
    CHECK(fitted.max_deviation >= nearest * (1.0 - 1e-12));
  }
  CHECK(fitted.max_deviation <= FitOptions{}.tolerance);  // each piece is fitted within tolerance
}
