// Nearest point on the real strokes: every fitted element of every embedded character, placed in
// metres with the default SceneLayout, with points where a pen would be (within 5 mm).
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "eval/nearest_point_reference.hpp"

using namespace calligraphy;

TEST_CASE("exact meets 1e-12 of the polygon length on every element of the embedded characters",
          "[nearest_point][corpus]") {
  const CharacterLibrary library = CharacterLibrary::embedded();
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int elements = 0;
  int by_degree[kMaxElementDegree + 1] = {};
  for (const char32_t c : library.characters()) {
    const Scene scene = Scene::lay_out({library.load(c)});
    for (const PlacedStroke& stroke : scene.characters.front().strokes) {
      for (const StrokeElement& element : stroke.elements) {
        ++elements;
        ++by_degree[element.degree];
        for (int query = 0; query < 3; ++query) {
          const double angle = 2 * std::numbers::pi * unit(random);
          const Vec2 p =
              element.point(unit(random)) + 5e-3 * unit(random) * Vec2(std::cos(angle), std::sin(angle));
          const NearestPoint result = nearest_point(element, p);
          const auto reference = cli::reference_nearest_point(element, p);
          INFO("U+" << std::hex << static_cast<unsigned>(c) << std::dec << ", degree " << element.degree);
          REQUIRE(std::isfinite(result.distance));
          CHECK(std::abs(result.distance - static_cast<double>(reference.distance)) <=
                1e-12 * element.polygon_length());
        }
      }
    }
  }
  CHECK(elements > 400);  // not an empty loop: 58 characters, about 400 strokes
  CHECK(by_degree[1] > 0);
  CHECK(by_degree[3] > 0);
}

TEST_CASE("The tracker follows a pen moving along real strokes 1 mm off with the exact distance",
          "[nearest_point][tracker][corpus]") {
  const CharacterLibrary library = CharacterLibrary::embedded();
  for (const char32_t c : std::u32string(U"永我九乙")) {
    const Scene scene = Scene::lay_out({library.load(c)});
    for (const PlacedStroke& stroke : scene.characters.front().strokes) {
      for (const StrokeElement& element : stroke.elements) {
        NearestPointTracker tracker;
        for (int tick = 0; tick <= 400; ++tick) {  // 0.4 s along the element at 1 kHz
          const double t = tick / 400.0;
          const Vec2 tangent = element.unit_tangent(t);
          const Vec2 p = element.point(t) + 1e-3 * Vec2(-tangent.y(), tangent.x());
          const NearestPoint tracked = tracker.update(element, p);
          const NearestPoint exact = nearest_point(element, p);
          INFO("U+" << std::hex << static_cast<unsigned>(c) << std::dec << ", tick " << tick);
          REQUIRE(tracked.distance <= exact.distance + 1e-4);  // within the tracker's hysteresis
          REQUIRE(tracked.distance >= exact.distance - 1e-15);
        }
      }
    }
  }
}
