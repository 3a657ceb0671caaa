#pragma once
// Query sets for measuring the nearest-point methods (`calligraphy bench nearest`, bench/).
// A scenario is a name, a one-line description and a function producing queries (an element and a
// point) for one degree. Adding one is one more entry in the list returned by
// `nearest_point_scenarios()`.
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "calligraphy/model/element.hpp"

namespace calligraphy::cli {

/// One query: the nearest point of `point` on `element` (both in m).
struct NearestPointQuery {
  StrokeElement element;
  Vec2 point = Vec2::Zero();
};

struct NearestPointScenario {
  std::string name;         ///< short identifier, used in tables and JSON
  std::string description;  ///< one line for the docs
  /// About `count` queries on elements of `degree` (1..4); none when the scenario has no element of
  /// that degree (e.g. a cusp needs degree >= 2).
  std::function<std::vector<NearestPointQuery>(int degree, int count, std::mt19937_64& random)> make;
};

/// The built-in scenarios: real strokes of the embedded characters, random curves in a 50 mm box (near
/// and far queries) and the extremes.
std::vector<NearestPointScenario> nearest_point_scenarios();

/// Every fitted element of every embedded character, each character laid out alone with the default
/// SceneLayout (60 mm box centred at the origin of the paper), control points in m.
std::vector<StrokeElement> corpus_elements();

/// Random queries within `max_offset_m` of random curves in a box of side `box_m` whose lower corner
/// is at `corner_m`; shared by the scenarios and the Google Benchmark program.
std::vector<NearestPointQuery> random_curve_queries(int degree, int count, std::mt19937_64& random,
                                                    double box_m, const Vec2& corner_m, double min_offset_m,
                                                    double max_offset_m);

}  // namespace calligraphy::cli
