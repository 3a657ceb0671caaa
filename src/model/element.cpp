#include "calligraphy/model/element.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// A fixed message per point (no formatting): cheap enough for any caller, and it names the point.
[[noreturn]] void throw_not_finite(const char* function, int index) {
  static constexpr const char* kPoint[] = {"0", "1", "2", "3", "4"};
  throw InvalidArgument(std::string(function) + ": control point " + kPoint[index] + " is not finite");
}

}  // namespace

StrokeElement StrokeElement::line(const Vec2& a, const Vec2& b) {
  if (!a.allFinite()) throw_not_finite("StrokeElement::line", 0);
  if (!b.allFinite()) throw_not_finite("StrokeElement::line", 1);
  StrokeElement e;
  e.kind = ElementKind::line;
  e.degree = 1;
  e.control[0] = a;
  e.control[1] = b;
  return e;
}

StrokeElement StrokeElement::bezier(const Vec2* points, int count) {
  if (count < 3 || count > kMaxElementDegree + 1) {
    throw InvalidArgument("StrokeElement::bezier: " + std::to_string(count) +
                          " control points given, a CSE takes 3 to 5");
  }
  for (int i = 0; i < count; ++i) {
    if (!points[i].allFinite()) throw_not_finite("StrokeElement::bezier", i);
  }
  StrokeElement e;
  e.kind = ElementKind::bezier;
  e.degree = count - 1;
  for (int i = 0; i < count; ++i) e.control[static_cast<std::size_t>(i)] = points[i];
  return e;
}

Vec2 StrokeElement::point(double t) const {
  std::array<Vec2, kMaxElementDegree + 1> p = control;
  for (int r = 1; r <= degree; ++r) {
    for (int i = 0; i <= degree - r; ++i) {
      p[static_cast<std::size_t>(i)] =
          (1.0 - t) * p[static_cast<std::size_t>(i)] + t * p[static_cast<std::size_t>(i + 1)];
    }
  }
  return p[0];
}

Vec2 StrokeElement::derivative(double t) const {
  // B'(t) = n * sum (P_{i+1} - P_i) B_{i,n-1}(t), evaluated by de Casteljau on the hodograph.
  std::array<Vec2, kMaxElementDegree> d{};
  for (int i = 0; i < degree; ++i) {
    d[static_cast<std::size_t>(i)] =
        control[static_cast<std::size_t>(i + 1)] - control[static_cast<std::size_t>(i)];
  }
  for (int r = 1; r < degree; ++r) {
    for (int i = 0; i < degree - r; ++i) {
      d[static_cast<std::size_t>(i)] =
          (1.0 - t) * d[static_cast<std::size_t>(i)] + t * d[static_cast<std::size_t>(i + 1)];
    }
  }
  return static_cast<double>(degree) * d[0];
}

Vec2 StrokeElement::unit_tangent(double t) const {
  const Vec2 d = derivative(t);
  const double n = d.norm();
  if (n > 1e-12 * (polygon_length() + 1e-300)) return d / n;
  // A vanishing derivative (cusp, coincident control points): use the chord.
  const Vec2 chord = end() - start();
  const double c = chord.norm();
  if (c > 0.0) return chord / c;
  return Vec2::UnitX();
}

double StrokeElement::polygon_length() const {
  double length = 0.0;
  for (int i = 0; i < degree; ++i) {
    length += (control[static_cast<std::size_t>(i + 1)] - control[static_cast<std::size_t>(i)]).norm();
  }
  return length;
}

namespace {
// 5-point Gauss-Legendre on [a, b] of |B'(t)|.
double gauss5(const StrokeElement& e, double a, double b) {
  static constexpr double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640,
                                  0.9061798459386640};
  static constexpr double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                                  0.2369268850561891, 0.2369268850561891};
  const double half = 0.5 * (b - a);
  const double mid = 0.5 * (a + b);
  double sum = 0.0;
  for (int i = 0; i < 5; ++i) sum += w[i] * e.derivative(mid + half * x[i]).norm();
  return sum * half;
}

double adaptive_length(const StrokeElement& e, double a, double b, double whole, double tolerance,
                       int depth) {
  const double mid = 0.5 * (a + b);
  const double left = gauss5(e, a, mid);
  const double right = gauss5(e, mid, b);
  if (depth >= 20 || std::abs(left + right - whole) <= tolerance) return left + right;
  return adaptive_length(e, a, mid, left, 0.5 * tolerance, depth + 1) +
         adaptive_length(e, mid, b, right, 0.5 * tolerance, depth + 1);
}
}  // namespace

double StrokeElement::arc_length() const {
  if (degree == 1) return (end() - start()).norm();
  const double whole = gauss5(*this, 0.0, 1.0);
  return adaptive_length(*this, 0.0, 1.0, whole, 1e-9 * (polygon_length() + 1e-300), 0);
}

bool feature_plane_passed(const StrokeElement& element, const Vec2& tip, double margin_m) noexcept {
  return element.unit_tangent(1.0).dot(tip - element.end()) > margin_m;
}

}  // namespace calligraphy
