#include "eval/nearest_point_scenarios.hpp"

#include <cmath>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy::cli {

namespace {

constexpr double kMillimetre = 1e-3;
constexpr double kPi = 3.14159265358979323846;

double uniform(std::mt19937_64& random, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(random);
}

Vec2 random_direction(std::mt19937_64& random) {
  const double angle = uniform(random, 0.0, 2.0 * kPi);
  return {std::cos(angle), std::sin(angle)};
}

Vec2 random_point_in_box(std::mt19937_64& random, const Vec2& corner, double side) {
  return corner + Vec2(uniform(random, 0.0, side), uniform(random, 0.0, side));
}

StrokeElement element_from(const std::vector<Vec2>& points) {
  if (points.size() == 2) return StrokeElement::line(points[0], points[1]);
  return StrokeElement::bezier(points.data(), static_cast<int>(points.size()));
}

// The same curve one degree higher (degree elevation), so a cubic extreme also exists as a quartic.
StrokeElement elevate(const StrokeElement& element) {
  const int n = element.degree;
  std::vector<Vec2> points(static_cast<std::size_t>(n) + 2);
  points.front() = element.start();
  points.back() = element.end();
  for (int i = 1; i <= n; ++i) {
    const double a = static_cast<double>(i) / (n + 1);
    points[static_cast<std::size_t>(i)] = a * element.control[static_cast<std::size_t>(i - 1)] +
                                          (1.0 - a) * element.control[static_cast<std::size_t>(i)];
  }
  return element_from(points);
}

std::vector<Vec2> millimetres(std::initializer_list<Vec2> points) {
  std::vector<Vec2> result;
  for (const Vec2& point : points) result.push_back(point * kMillimetre);
  return result;
}

// A point at a random distance in [min_offset, max_offset] from a random point of the element.
Vec2 point_near(const StrokeElement& element, std::mt19937_64& random, double min_offset, double max_offset) {
  return element.point(uniform(random, 0.0, 1.0)) +
         uniform(random, min_offset, max_offset) * random_direction(random);
}

StrokeElement random_element(int degree, std::mt19937_64& random, const Vec2& corner, double side) {
  std::vector<Vec2> points;
  for (int i = 0; i <= degree; ++i) points.push_back(random_point_in_box(random, corner, side));
  return element_from(points);
}

// Queries on one fixed element (a cusp, a loop): half near the curve, half near a point of interest.
std::vector<NearestPointQuery> queries_on(const StrokeElement& element, const Vec2& focus, int count,
                                          std::mt19937_64& random) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const Vec2 point = i % 2 == 0 ? point_near(element, random, 0.0, 5 * kMillimetre)
                                  : focus + uniform(random, 0.0, 5 * kMillimetre) * random_direction(random);
    queries.push_back({element, point});
  }
  return queries;
}

std::vector<NearestPointQuery> cusp_queries(int degree, int count, std::mt19937_64& random) {
  if (degree < 2) return {};
  // A quadratic whose middle control point is passed twice turns back at t = 0.5; the cubic
  // (0,0),(30,30),(0,30),(30,0) mm has its cusp at t = 0.5 (B'(0.5) = 0).
  StrokeElement element = degree == 2 ? element_from(millimetres({{0, 0}, {30, 30}, {0, 0}}))
                                      : element_from(millimetres({{0, 0}, {30, 30}, {0, 30}, {30, 0}}));
  if (degree == 4) element = elevate(element);
  return queries_on(element, element.point(0.5), count, random);
}

std::vector<NearestPointQuery> loop_queries(int degree, int count, std::mt19937_64& random) {
  if (degree < 3) return {};  // a quadratic cannot loop
  StrokeElement element = element_from(millimetres({{0, 0}, {45, 30}, {-15, 30}, {30, 0}}));
  if (degree == 4) element = elevate(element);
  // The focus is inside the loop, where the nearest point jumps between its branches.
  return queries_on(element, element.point(0.5) + Vec2(0.0, -4 * kMillimetre), count, random);
}

std::vector<NearestPointQuery> coincident_queries(int degree, int count, std::mt19937_64& random) {
  if (degree < 2) return {};
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    StrokeElement element = random_element(degree, random, Vec2::Zero(), 50 * kMillimetre);
    element.control[1] = element.control[0];                                                 // B'(0) = 0
    if (degree >= 3) element.control[static_cast<std::size_t>(degree - 1)] = element.end();  // B'(1) = 0
    queries.push_back({element, point_near(element, random, 0.0, 5 * kMillimetre)});
  }
  return queries;
}

std::vector<NearestPointQuery> zero_length_queries(int degree, int count, std::mt19937_64& random) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const Vec2 point = random_point_in_box(random, Vec2::Zero(), 50 * kMillimetre);
    StrokeElement element = element_from(std::vector<Vec2>(static_cast<std::size_t>(degree) + 1, point));
    const double offset = i % 4 == 0 ? 0.0 : uniform(random, 0.0, 5 * kMillimetre);
    queries.push_back({element, point + offset * random_direction(random)});
  }
  return queries;
}

std::vector<NearestPointQuery> on_curve_queries(int degree, int count, std::mt19937_64& random) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const StrokeElement element = random_element(degree, random, Vec2::Zero(), 50 * kMillimetre);
    queries.push_back({element, element.point(uniform(random, 0.0, 1.0))});
  }
  return queries;
}

// P at an end, or on the extension of the end tangent beyond it.
std::vector<NearestPointQuery> end_queries(int degree, int count, std::mt19937_64& random) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const StrokeElement element = random_element(degree, random, Vec2::Zero(), 50 * kMillimetre);
    const double beyond = uniform(random, 0.0, 5 * kMillimetre);
    Vec2 point;
    switch (i % 4) {
      case 0:
        point = element.start();
        break;
      case 1:
        point = element.end();
        break;
      case 2:
        point = element.start() - beyond * element.unit_tangent(0.0);
        break;
      default:
        point = element.end() + beyond * element.unit_tangent(1.0);
        break;
    }
    queries.push_back({element, point});
  }
  return queries;
}

std::vector<NearestPointQuery> far_queries(int degree, int count, std::mt19937_64& random) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const StrokeElement element = random_element(degree, random, Vec2::Zero(), 50 * kMillimetre);
    const double distance = i % 2 == 0 ? 1.0 : 100.0;
    queries.push_back({element, element.point(0.5) + distance * random_direction(random)});
  }
  return queries;
}

// P at the centre of the osculating circle of a random point (the distance is stationary to third
// order there: f has a double root).
std::vector<NearestPointQuery> centre_of_curvature_queries(int degree, int count, std::mt19937_64& random) {
  if (degree < 2) return {};
  std::vector<NearestPointQuery> queries;
  while (static_cast<int>(queries.size()) < count) {
    const StrokeElement element = random_element(degree, random, Vec2::Zero(), 50 * kMillimetre);
    const double t = uniform(random, 0.0, 1.0);
    const Vec2 first = element.derivative(t);
    const double h = 1e-4;
    const Vec2 second = (element.derivative(t + h) - element.derivative(t - h)) / (2 * h);
    const double speed = first.norm();
    const double cross = first.x() * second.y() - first.y() * second.x();
    if (speed < 1e-3 || cross == 0.0) continue;
    const double radius = speed * speed * speed / cross;  // signed, towards the left normal
    if (std::abs(radius) > 1.0) continue;                 // nearly straight: skip
    const Vec2 normal(-first.y() / speed, first.x() / speed);
    queries.push_back({element, element.point(t) + radius * normal});
  }
  return queries;
}

// Queries near the real strokes: a random element of the degree from the corpus, P within 5 mm of a
// random point on it (where a pen is while it writes or approaches a stroke).
std::vector<NearestPointQuery> corpus_queries(int degree, int count, std::mt19937_64& random) {
  static const std::vector<StrokeElement> elements = corpus_elements();
  std::vector<const StrokeElement*> of_degree;
  for (const StrokeElement& element : elements) {
    if (element.degree == degree) of_degree.push_back(&element);
  }
  std::vector<NearestPointQuery> queries;
  if (of_degree.empty()) return queries;
  std::uniform_int_distribution<std::size_t> pick(0, of_degree.size() - 1);
  for (int i = 0; i < count; ++i) {
    const StrokeElement& element = *of_degree[pick(random)];
    queries.push_back({element, point_near(element, random, 0.0, 5 * kMillimetre)});
  }
  return queries;
}

std::function<std::vector<NearestPointQuery>(int, int, std::mt19937_64&)> random_scenario(double box,
                                                                                          const Vec2& corner,
                                                                                          double min_offset,
                                                                                          double max_offset) {
  return [=](int degree, int count, std::mt19937_64& random) {
    return random_curve_queries(degree, count, random, box, corner, min_offset, max_offset);
  };
}

}  // namespace

std::vector<StrokeElement> corpus_elements() {
  const CharacterLibrary library = CharacterLibrary::embedded();
  std::vector<StrokeElement> elements;
  for (const char32_t code_point : library.characters()) {
    const Scene scene = Scene::lay_out({library.load(code_point)});
    for (const PlacedStroke& stroke : scene.characters.front().strokes) {
      elements.insert(elements.end(), stroke.elements.begin(), stroke.elements.end());
    }
  }
  return elements;
}

std::vector<NearestPointQuery> random_curve_queries(int degree, int count, std::mt19937_64& random,
                                                    double box_m, const Vec2& corner_m, double min_offset_m,
                                                    double max_offset_m) {
  std::vector<NearestPointQuery> queries;
  for (int i = 0; i < count; ++i) {
    const StrokeElement element = random_element(degree, random, corner_m, box_m);
    queries.push_back({element, point_near(element, random, min_offset_m, max_offset_m)});
  }
  return queries;
}

std::vector<NearestPointScenario> nearest_point_scenarios() {
  const double mm = kMillimetre;
  const Vec2 far_corner(100.0, 100.0);
  return {
      {"corpus",
       "fitted elements of the " + std::to_string(CharacterLibrary::embedded().characters().size()) +
           " embedded characters, each character placed alone in the default 60 mm box; P within 5 mm of a "
           "random point of a random element",
       corpus_queries},
      {"random_near", "random curves in a 50 mm box, P within 5 mm of a random curve point",
       random_scenario(50 * mm, Vec2::Zero(), 0.0, 5 * mm)},
      {"random_out", "random curves in a 50 mm box, P 5 to 50 mm from a random curve point",
       random_scenario(50 * mm, Vec2::Zero(), 5 * mm, 50 * mm)},
      {"cusp",
       "cusp at t = 0.5 (cubic (0,0),(30,30),(0,30),(30,0) mm; quadratic turning back; quartic by elevation)",
       cusp_queries},
      {"loop", "self-intersecting cubic (0,0),(45,30),(-15,30),(30,0) mm and its quartic elevation",
       loop_queries},
      {"coincident", "P0 = P1 and P(n-1) = Pn (B' = 0 at the ends), random in a 50 mm box",
       coincident_queries},
      {"zero_length", "all control points coincident; P on them or within 5 mm", zero_length_queries},
      {"on_curve", "P = B(u) for random u", on_curve_queries},
      {"ends", "P at an end or on the end tangent's extension up to 5 mm beyond", end_queries},
      {"far", "P 1 m or 100 m from a 50 mm curve", far_queries},
      {"centre_of_curvature", "P at the centre of curvature of a random curve point (radius < 1 m)",
       centre_of_curvature_queries},
      {"scale_1e-6", "curves in a 1e-6 m box, P within 1e-7 m",
       random_scenario(1e-6, Vec2::Zero(), 0.0, 1e-7)},
      {"scale_1e2", "curves in a 1e2 m box, P within 10 m", random_scenario(1e2, Vec2::Zero(), 0.0, 10.0)},
      {"offset_1e2", "50 mm curves at (100 m, 100 m), P within 5 mm",
       random_scenario(50 * mm, far_corner, 0.0, 5 * mm)},
      {"offset_1e2_scale_1e-6", "1e-6 m curves at (100 m, 100 m), P within 1e-7 m",
       random_scenario(1e-6, far_corner, 0.0, 1e-7)},
  };
}

}  // namespace calligraphy::cli
