// Median polyline -> stroke elements (paper sections 3.3-3.4). First version: corners found by summed
// turning over a window (REFERENCE.md section 2), straight pieces as LSEs, bent pieces as least-squares
// Bezier CSEs, split at the worst point until within tolerance.
#include "calligraphy/fitting.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "calligraphy/errors.hpp"
#include "calligraphy/typical_strokes.hpp"
#include "model/polyline.hpp"

namespace calligraphy {
namespace {

constexpr double kBrushHookTurnDeg = 30.0;
constexpr double kClusterTurnDeg = 10.0;
constexpr int kMaxSplitDepth = 6;

std::vector<Vec2> trim_brush_hooks(std::vector<Vec2> pts, const FitOptions& options) {
  const auto is_hook = [&](const Vec2& a, const Vec2& b, const Vec2& c) {
    const Vec2 hook = b - a;
    const Vec2 body = c - b;
    return hook.norm() < options.hook_trim_length && body.norm() > hook.norm() &&
           std::abs(turn_deg(hook, body)) > kBrushHookTurnDeg;
  };
  if (pts.size() >= 3 && is_hook(pts[0], pts[1], pts[2])) pts.erase(pts.begin());
  const std::size_t n = pts.size();
  if (n >= 3 && is_hook(pts[n - 1], pts[n - 2], pts[n - 3])) pts.pop_back();
  return pts;
}

// Indices of corner vertices, after replacing rounded corners (a run of vertices turning the same way)
// by the intersection of the lines that enter and leave them. The window slides along the arc every
// few units, so a corner rounded over several vertices is summed whole wherever its centre lies.
std::vector<std::size_t> find_corners(std::vector<Vec2>& pts, const FitOptions& options) {
  const std::size_t n = pts.size();
  if (n < 3) return {};
  std::vector<double> turn(n, 0.0);
  std::vector<double> arc(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) arc[i] = arc[i - 1] + (pts[i] - pts[i - 1]).norm();
  for (std::size_t i = 1; i + 1 < n; ++i) turn[i] = turn_deg(pts[i] - pts[i - 1], pts[i + 1] - pts[i]);

  // Clusters [first, last] of interior vertices forming one corner each.
  std::vector<std::pair<std::size_t, std::size_t>> clusters;
  const double step = std::max(1.0, options.corner_window / 12.0);
  for (double centre = 0.0; centre <= arc[n - 1]; centre += step) {
    double windowed = 0.0;
    for (std::size_t j = 1; j + 1 < n; ++j) {
      if (std::abs(arc[j] - centre) <= options.corner_window) windowed += turn[j];
    }
    if (std::abs(windowed) < options.corner_angle_deg) continue;
    std::size_t first = n;
    std::size_t last = 0;
    for (std::size_t j = 1; j + 1 < n; ++j) {
      if (std::abs(arc[j] - centre) <= options.corner_window && turn[j] * windowed > 0.0 &&
          std::abs(turn[j]) > kClusterTurnDeg) {
        first = std::min(first, j);
        last = std::max(last, j);
      }
    }
    if (first > last) continue;
    if (!clusters.empty() && first <= clusters.back().second + 1 && turn[first] * turn[clusters.back().first] > 0.0) {
      clusters.back().second = std::max(clusters.back().second, last);
    } else if (clusters.empty() || first > clusters.back().second) {
      clusters.emplace_back(first, last);
    }
  }

  // Snap each cluster to one vertex, from the last so that earlier indices stay valid.
  std::vector<std::size_t> corners;
  for (auto it = clusters.rbegin(); it != clusters.rend(); ++it) {
    auto [first, last] = *it;
    std::size_t sharpest = first;
    for (std::size_t j = first; j <= last; ++j) {
      if (std::abs(turn[j]) > std::abs(turn[sharpest])) sharpest = j;
    }
    std::size_t corner = sharpest;
    if (first != last) {
      const Vec2 a = pts[first - 1];
      const Vec2 da = pts[first] - a;
      const Vec2 b = pts[last + 1];
      const Vec2 db = pts[last] - b;
      const double denom = da.x() * db.y() - da.y() * db.x();
      if (std::abs(denom) > 1e-9 * da.norm() * db.norm()) {
        const double s = ((b - a).x() * db.y() - (b - a).y() * db.x()) / denom;
        const Vec2 x = a + s * da;
        if (s > 0.0 && (x - pts[sharpest]).norm() <= options.corner_window) {
          pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(first + 1),
                    pts.begin() + static_cast<std::ptrdiff_t>(last + 1));
          pts[first] = x;
          for (auto& c : corners) c -= last - first;
          corner = first;
        }
      }
    }
    corners.push_back(corner);
  }
  std::reverse(corners.begin(), corners.end());
  return corners;
}

// Direction of motion of a polyline between two fractions of its arc length, y-up degrees.
double chord_direction(std::span<const Vec2> pts, double from, double to) {
  const double length = polyline_length(pts);
  const auto at = [&](double fraction) {
    double remaining = fraction * length;
    for (std::size_t i = 1; i < pts.size(); ++i) {
      const double segment = (pts[i] - pts[i - 1]).norm();
      if (remaining <= segment && segment > 0.0) return Vec2(pts[i - 1] + (pts[i] - pts[i - 1]) * (remaining / segment));
      remaining -= segment;
    }
    return Vec2(pts.back());
  };
  return direction_deg(at(to) - at(from));
}

double bernstein(int n, int i, double t) {
  double binom = 1.0;
  for (int k = 1; k <= i; ++k) binom = binom * (n - k + 1) / k;
  // x^0, x^1 and x^2 multiplied out (one rounding, as pow's correctly rounded result); pow above.
  const auto power = [](double x, int e) {
    return e == 0 ? 1.0 : e == 1 ? x : e == 2 ? x * x : std::pow(x, e);
  };
  return binom * power(t, i) * power(1.0 - t, n - i);
}

// Least-squares Bezier of `degree` with fixed endpoints through `samples` at chord-length parameters,
// with two passes of Newton reparameterisation.
StrokeElement fit_bezier(const std::vector<Vec2>& samples, int degree) {
  const std::size_t m = samples.size();
  std::vector<double> t(m, 0.0);
  double total = 0.0;
  for (std::size_t k = 1; k < m; ++k) {
    total += (samples[k] - samples[k - 1]).norm();
    t[k] = total;
  }
  for (auto& v : t) v /= total;
  std::array<Vec2, kMaxElementDegree + 1> ctrl = StrokeElement{}.control;
  ctrl[0] = samples.front();
  ctrl[static_cast<std::size_t>(degree)] = samples.back();
  StrokeElement element;
  for (int pass = 0; pass < 3; ++pass) {
    Eigen::MatrixXd a(static_cast<Eigen::Index>(m), degree - 1);
    Eigen::MatrixXd rhs(static_cast<Eigen::Index>(m), 2);
    for (std::size_t k = 0; k < m; ++k) {
      const auto row = static_cast<Eigen::Index>(k);
      for (int i = 1; i < degree; ++i) a(row, i - 1) = bernstein(degree, i, t[k]);
      const Vec2 r = samples[k] - bernstein(degree, 0, t[k]) * ctrl[0] -
                     bernstein(degree, degree, t[k]) * ctrl[static_cast<std::size_t>(degree)];
      rhs(row, 0) = r.x();
      rhs(row, 1) = r.y();
    }
    const Eigen::MatrixXd inner = a.colPivHouseholderQr().solve(rhs);
    for (int i = 1; i < degree; ++i) ctrl[static_cast<std::size_t>(i)] = Vec2(inner(i - 1, 0), inner(i - 1, 1));
    element = StrokeElement::bezier(ctrl.data(), degree + 1);
    for (std::size_t k = 1; k + 1 < m; ++k) {  // Newton step on |B(t)-p|^2
      const Vec2 d = element.point(t[k]) - samples[k];
      const Vec2 d1 = element.derivative(t[k]);
      const double h = 1e-6;
      const Vec2 d2 = (element.derivative(std::min(1.0, t[k] + h)) - element.derivative(std::max(0.0, t[k] - h))) /
                      (std::min(1.0, t[k] + h) - std::max(0.0, t[k] - h));
      const double denom = d1.squaredNorm() + d.dot(d2);
      if (denom > 0.0) t[k] = std::clamp(t[k] - d.dot(d1) / denom, 0.0, 1.0);
    }
  }
  return element;
}

double max_deviation(const std::vector<Vec2>& samples, const StrokeElement& element) {
  const auto curve = sample_element(element, 64);
  return max_distance_to_polyline(samples, curve);
}

void fit_piece(std::span<const Vec2> pts, const FitOptions& options, int depth, std::vector<StrokeElement>& out) {
  if (pts.size() <= 2 || max_chord_deviation(pts) <= options.tolerance) {
    out.push_back(StrokeElement::line(pts.front(), pts.back()));
    return;
  }
  const auto samples = resample(pts, std::max(2.0, options.tolerance * 0.5));
  StrokeElement best;
  double best_deviation = std::numeric_limits<double>::infinity();
  for (int degree = 2; degree <= options.max_degree; ++degree) {
    const StrokeElement candidate = fit_bezier(samples, degree);
    const double deviation = max_deviation(samples, candidate);
    if (deviation < best_deviation) {
      best = candidate;
      best_deviation = deviation;
    }
    if (deviation <= options.tolerance) break;
  }
  if (best_deviation <= options.tolerance || depth >= kMaxSplitDepth) {
    out.push_back(best);
    return;
  }
  const std::size_t split = farthest_from_chord(pts);
  fit_piece(pts.subspan(0, split + 1), options, depth + 1, out);
  fit_piece(pts.subspan(split), options, depth + 1, out);
}

void check_options(const FitOptions& o) {
  if (!(o.tolerance > 0.0) || !(o.corner_angle_deg > 0.0) || !(o.corner_window > 0.0) ||
      !(o.hook_trim_length >= 0.0) || o.max_degree < 2 || o.max_degree > kMaxElementDegree) {
    throw InvalidArgument("FitOptions out of range: tolerance " + std::to_string(o.tolerance) + ", corner angle " +
                          std::to_string(o.corner_angle_deg) + ", window " + std::to_string(o.corner_window) +
                          ", max degree " + std::to_string(o.max_degree) + " (2-4)");
  }
}

}  // namespace

FittedStroke fit_stroke(std::span<const Vec2> median, const FitOptions& options) {
  check_options(options);
  if (median.empty()) throw InvalidArgument("fit_stroke: empty median");
  for (std::size_t i = 0; i < median.size(); ++i) {
    if (!median[i].allFinite()) throw InvalidArgument("fit_stroke: median point " + std::to_string(i) + " is not finite");
  }
  FittedStroke fitted;
  fitted.stroke.median.assign(median.begin(), median.end());
  std::vector<Vec2> pts = trim_brush_hooks(without_repeats(median), options);
  if (pts.size() == 1) {  // a single point: a zero-length LSE, always inside its constraint space (rule d)
    fitted.stroke.elements.push_back(StrokeElement::line(pts[0], pts[0]));
    fitted.pieces.push_back({0.0, 0.0, 0.0, 0, 1});
  } else {
    std::vector<std::size_t> cuts = find_corners(pts, options);
    cuts.insert(cuts.begin(), 0);
    cuts.push_back(pts.size() - 1);
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
      const std::span<const Vec2> piece(pts.data() + cuts[k], cuts[k + 1] - cuts[k] + 1);
      StrokePiece info;
      info.first_element = fitted.stroke.elements.size();
      fit_piece(piece, options, 0, fitted.stroke.elements);
      info.end_element = fitted.stroke.elements.size();
      // Interior chords, not end tangents: brush entries and exits bend the ends of the medians.
      info.start_direction_deg = chord_direction(piece, 0.1, 0.4);
      info.end_direction_deg = chord_direction(piece, 0.6, 0.95);
      info.length = polyline_length(piece);
      fitted.pieces.push_back(info);
    }
  }
  // Max deviation of the kept median points from the whole fitted stroke.
  std::vector<Vec2> curve;
  for (const auto& e : fitted.stroke.elements) {
    const auto s = sample_element(e, 64);
    curve.insert(curve.end(), s.begin(), s.end());
  }
  fitted.max_deviation = max_distance_to_polyline(pts, curve);

  fitted.stroke.typical_id = classify_pieces(fitted.pieces);
  fitted.stroke.attraction_factors.assign(fitted.stroke.feature_point_count(),
                                          typical_stroke(fitted.stroke.typical_id).default_attraction);
  return fitted;
}

int classify_pieces(std::span<const StrokePiece> all_pieces) {
  // No typical stroke starts with a short piece: a short first piece is the brush's entry.
  std::span<const StrokePiece> pieces = all_pieces;
  double whole = 0.0;
  for (const auto& p : all_pieces) whole += p.length;
  if (pieces.size() > 1 && pieces.front().length < 0.2 * whole) pieces = pieces.subspan(1);
  double total = 0.0;
  for (const auto& p : pieces) total += p.length;
  // Dots are short strokes; hooks and ticks are short relative to their stroke (data units).
  constexpr double kDotLength = 230.0;
  constexpr double kShortFraction = 0.3;
  constexpr double kShortMismatchCost = 40.0;
  int best_id = 1;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const TypicalStroke& t : typical_strokes()) {
    const std::size_t count = std::min(t.pieces.size(), pieces.size());
    double cost = 90.0 * static_cast<double>(std::max(t.pieces.size(), pieces.size()) - count);
    for (std::size_t k = 0; k < count; ++k) {
      const StrokePiece& p = pieces[k];
      const StrokePieceTemplate& q = t.pieces[k];
      cost += std::abs(wrap_deg(p.start_direction_deg - q.start_direction_deg));
      cost += std::abs(wrap_deg(p.end_direction_deg - q.end_direction_deg));
      const bool is_short = pieces.size() == 1 ? p.length < kDotLength : p.length < kShortFraction * total;
      if (is_short != q.short_piece) cost += kShortMismatchCost;
    }
    if (cost < best_cost) {
      best_cost = cost;
      best_id = t.id;
    }
  }
  return best_id;
}

Character fit_character(char32_t code_point, const std::vector<std::vector<Vec2>>& medians, std::string source,
                        const FitOptions& options) {
  Character character;
  character.code_point = code_point;
  character.source = std::move(source);
  character.strokes.reserve(medians.size());
  for (const auto& median : medians) character.strokes.push_back(fit_stroke(median, options).stroke);
  return character;
}

}  // namespace calligraphy
