// Median polyline -> stroke elements (paper sections 3.3-3.4). Corners found by summed turning over a
// window (model/corner_search.cpp), straight pieces as LSEs, bent pieces as least-squares Bezier CSEs,
// split at the worst point until within tolerance. Every loop is bounded by the number of points.
#include "calligraphy/model/fitting.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/polyline.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "model/corner_search.hpp"

namespace calligraphy {
namespace {

constexpr double kBrushHookTurnDeg = 30.0;
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

// Direction of motion of a polyline between two fractions of its arc length, y-up degrees.
double chord_direction(std::span<const Vec2> pts, double from, double to) {
  const double length = polyline_length(pts);
  const auto at = [&](double fraction) {
    double remaining = fraction * length;
    for (std::size_t i = 1; i < pts.size(); ++i) {
      const double segment = (pts[i] - pts[i - 1]).norm();
      if (remaining <= segment && segment > 0.0)
        return Vec2(pts[i - 1] + (pts[i] - pts[i - 1]) * (remaining / segment));
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
    for (int i = 1; i < degree; ++i)
      ctrl[static_cast<std::size_t>(i)] = Vec2(inner(i - 1, 0), inner(i - 1, 1));
    element = StrokeElement::bezier(ctrl.data(), degree + 1);
    for (std::size_t k = 1; k + 1 < m; ++k) {  // Newton step on |B(t)-p|^2
      const Vec2 d = element.point(t[k]) - samples[k];
      const Vec2 d1 = element.derivative(t[k]);
      const double h = 1e-6;
      const Vec2 d2 =
          (element.derivative(std::min(1.0, t[k] + h)) - element.derivative(std::max(0.0, t[k] - h))) /
          (std::min(1.0, t[k] + h) - std::max(0.0, t[k] - h));
      const double denom = d1.squaredNorm() + d.dot(d2);
      if (denom > 0.0) t[k] = std::clamp(t[k] - d.dot(d1) / denom, 0.0, 1.0);
    }
  }
  return element;
}

// The max distance of the samples from the element; any value above `stop_above` once it is exceeded.
double max_deviation(const std::vector<Vec2>& samples, const StrokeElement& element, double stop_above) {
  const auto curve = sample_element(element, 64);
  return max_distance_to_polyline(samples, curve, stop_above);
}

void fit_piece(std::span<const Vec2> pts, const FitOptions& options, int depth,
               std::vector<StrokeElement>& out) {
  if (pts.size() <= 2 || max_chord_deviation(pts) <= options.tolerance) {
    out.push_back(StrokeElement::line(pts.front(), pts.back()));
    return;
  }
  // Samples every half tolerance, but no more than a number tied to the piece's points, so that far-flung
  // points (a hostile median) cost no more than near ones. It binds only on pieces longer than
  // 2 * (1024 + 8 n) data units, two box widths, so never on the 1024-box data (same samples as before).
  const double max_samples = 1024.0 + 8.0 * static_cast<double>(pts.size());
  const double spacing = std::max({2.0, options.tolerance * 0.5, polyline_length(pts) / max_samples});
  const auto samples = resample(pts, spacing);
  StrokeElement best;
  double best_deviation = std::numeric_limits<double>::infinity();
  // Before the depth limit a piece that no degree fits within tolerance is split, so a candidate's
  // deviation is needed only up to the tolerance; at the limit the least deviation picks the element.
  const double needed_up_to =
      depth >= kMaxSplitDepth ? std::numeric_limits<double>::infinity() : options.tolerance;
  for (int degree = 2; degree <= options.max_degree; ++degree) {
    const StrokeElement candidate = fit_bezier(samples, degree);
    const double deviation = max_deviation(samples, candidate, needed_up_to);
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

std::vector<Vec2> sample_elements(std::span<const StrokeElement> elements) {
  std::vector<Vec2> curve;
  for (const auto& e : elements) {
    const auto s = sample_element(e, 64);
    curve.insert(curve.end(), s.begin(), s.end());
  }
  return curve;
}

// Max deviation of the kept median points from the whole fitted stroke. Exact when it takes at most 64
// point-segment distances per point and curve sample, which a median of up to 64 points never exceeds;
// otherwise (a long median overlapping itself many times) the max distance of each piece's points to
// the piece's own elements, an upper bound, so that the work stays bounded by the number of points.
double stroke_deviation(std::span<const Vec2> pts, std::span<const std::size_t> cuts,
                        const FittedStroke& fitted) {
  const std::vector<Vec2> curve = sample_elements(fitted.stroke.elements);
  constexpr std::size_t kEvaluationsPerPoint = 64;
  if (const auto exact =
          max_distance_to_polyline_within(pts, curve, kEvaluationsPerPoint * (pts.size() + curve.size()))) {
    return *exact;
  }
  double bound = 0.0;
  for (std::size_t k = 0; k < fitted.pieces.size(); ++k) {
    const StrokePiece& piece = fitted.pieces[k];
    const auto own = std::span(fitted.stroke.elements)
                         .subspan(piece.first_element, piece.end_element - piece.first_element);
    bound = std::max(bound, max_distance_to_polyline(pts.subspan(cuts[k], cuts[k + 1] - cuts[k] + 1),
                                                     sample_elements(own)));
  }
  return bound;
}

void check_options(const FitOptions& o) {
  check_parameters(o);
  if (o.max_degree < 2 || o.max_degree > kMaxElementDegree) {
    throw InvalidArgument("FitOptions.max_degree = " + std::to_string(o.max_degree) + " must be in [2, " +
                          std::to_string(kMaxElementDegree) + "]");
  }
}

using FitField = ParameterField<FitOptions>;
constexpr ParameterRange kPositiveLength{.low_open = true};

constexpr std::array kFitFields{
    FitField{"tolerance", "", kPositiveLength,
             "largest deviation of the elements from the median, in data units", &FitOptions::tolerance},
    FitField{"corner_angle_deg", "deg", ParameterRange{.low = 0.0, .high = 180.0, .low_open = true},
             "least turn within the corner window that makes a corner", &FitOptions::corner_angle_deg},
    FitField{"corner_window", "", kPositiveLength, "arc length over which turning is summed, in data units",
             &FitOptions::corner_window},
    FitField{"hook_trim_length", "", ParameterRange{},
             "longest end segment trimmed as a brush hook, in data units", &FitOptions::hook_trim_length},
};

}  // namespace

std::span<const ParameterField<FitOptions>> ParameterTable<FitOptions>::fields() noexcept {
  return kFitFields;
}

FittedStroke fit_stroke(std::span<const Vec2> median, const FitOptions& options) {
  check_options(options);
  if (median.empty()) throw InvalidArgument("fit_stroke: empty median");
  for (std::size_t i = 0; i < median.size(); ++i) {
    if (!median[i].allFinite())
      throw InvalidArgument("fit_stroke: median point " + std::to_string(i) + " is not finite");
    if (median[i].cwiseAbs().maxCoeff() > kMaxFitCoordinate) {
      throw InvalidArgument("fit_stroke: median point " + std::to_string(i) +
                            " is beyond +-1e150 (lengths would overflow)");
    }
  }
  FittedStroke fitted;
  fitted.stroke.median.assign(median.begin(), median.end());
  std::vector<Vec2> pts = trim_brush_hooks(without_repeats(median), options);
  std::vector<std::size_t> cuts{0, 0};  // piece k spans pts[cuts[k]] to pts[cuts[k + 1]]
  if (pts.size() == 1) {  // a single point: a zero-length LSE, always inside its constraint space (rule d)
    fitted.stroke.elements.push_back(StrokeElement::line(pts[0], pts[0]));
    fitted.pieces.push_back({0.0, 0.0, 0.0, 0, 1});
  } else {
    cuts = detail::find_corners(pts, options);
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
      info.exit_turn_deg = wrap_deg(chord_direction(piece, 0.8, 1.0) - chord_direction(piece, 0.5, 0.8));
      fitted.pieces.push_back(info);
    }
  }
  fitted.max_deviation = stroke_deviation(pts, cuts, fitted);

  fitted.stroke.typical_id = classify_pieces(fitted.pieces);
  // Paper eq. 8: an attraction factor per feature point; corners (piece joints) pull harder so that the
  // writer is guided through the turn.
  const TypicalStroke& type = typical_stroke(fitted.stroke.typical_id);
  fitted.stroke.attraction_factors.assign(fitted.stroke.feature_point_count(), type.default_attraction);
  for (std::size_t k = 1; k < fitted.pieces.size(); ++k) {
    fitted.stroke.attraction_factors[fitted.pieces[k].first_element] = type.corner_attraction;
  }
  return fitted;
}

namespace {

// Forms in which hanzi-writer-data's medians show some typical strokes besides their canonical
// template, found by comparing with cnchar-order's labels (docs/classification.md): a corner rounded
// so widely that it is fitted as one bent piece, a zig-zag that is too small to make corners.
struct ObservedForm {
  int id;
  std::array<StrokePieceTemplate, 3> pieces;
  std::size_t count;
  double extra_cost;  // prior against the form (units of the template cost)
};
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr StrokePieceTemplate form_piece(double start, double end, double start_tol, double end_tol,
                                         bool hook = false, double min_length = 0.0,
                                         double max_length = kInf) {
  return piece_template(start, end, start_tol, end_tol, hook, min_length, max_length);
}
constexpr StrokePieceTemplate kFormHookLeft = form_piece(150, 150, 25, 25, true);
constexpr StrokePieceTemplate kNone{};
constexpr ObservedForm kObservedForms[] = {
    // 提 starting flat and rising at its end (乖 6, 些 4).
    {6, {form_piece(0, 27, 12, 6), kNone, kNone}, 1, 0.0},
    // Short vertical leaning right, as the left side of a small 口 (串 1, 京 3).
    {2, {form_piece(-58, -80, 14, 5, false, 150, 320), kNone, kNone}, 1, 0.0},
    // 横撇弯钩 (阝) whose 撇 and 弯 merge into one bent piece (哪 8, 啊 4).
    {16,
     {form_piece(10, 10, 20, 20), form_piece(-110, -73, 15, 10), form_piece(160, 160, 25, 25, true)},
     3,
     0.0},
    // 横折折撇 (辶 2) whose small zig-zag makes no corners: down-left turning down-right.
    {17, {form_piece(10, 10, 20, 20), form_piece(-110, -75, 20, 20), kNone}, 2, 1.0},
    // 竖弯钩 whose hook the median lacks (七 2, 他 5): a single bend from down to right.
    {24, {form_piece(-85, 35, 20, 20), kNone, kNone}, 1, 0.0},
    // 撇点 of 女 as a left part (妣 1, 姥 1): one bend from down-left to down-right.
    {28, {form_piece(-100, -50, 10, 10), kNone, kNone}, 1, 0.0},
    // 横折 ending with a brush tick too short for a hook (亩 4, 佃 4).
    {7,
     {form_piece(10, 10, 20, 20), form_piece(-95, -95, 20, 20), form_piece(150, 150, 25, 25, true, 0, 75)},
     3,
     0.0},
    // 竖弯钩 whose bend is a corner.
    {24, {form_piece(-95, -95, 20, 20), form_piece(0, 0, 25, 25), form_piece(90, 90, 25, 25, true)}, 3, 0.0},
    // 竖折折钩 whose second corner is rounded into the bend.
    {27, {form_piece(-95, -95, 20, 20), form_piece(15, -80, 25, 25), kFormHookLeft}, 3, 0.0},
};

// Extra costs of typical strokes that are rare in the data or that the medians mimic, so that they win
// only clearly.
double prior_cost(int id) {
  switch (id) {
    case 34:
      return 0.3;  // 长点
    case 37:
      return 0.5;  // 提捺
    case 23:
      return 0.5;  // 竖弯: in the data mostly a 竖弯钩 whose hook the median lacks
    case 39:
      return 1.0;  // 竖弯左: rare; a curved 撇 must not fall into it
    default:
      return 0.0;
  }
}

// A hook or tick is at most this fraction of its stroke's (entry-trimmed) length.
constexpr double kHookFraction = 0.35;

// Template cost (paper section 3.1, classification by template matching): squared direction errors
// in units of the tolerances, plus soft penalties for lengths and piece counts.
double template_cost(std::span<const StrokePiece> pieces, double total,
                     std::span<const StrokePieceTemplate> t) {
  constexpr double kPieceCountCost = 4.0;
  constexpr double kLengthScale = 40.0;  // data units per unit of cost (squared)
  constexpr double kFractionScale = 0.1;
  const std::size_t common = std::min(pieces.size(), t.size());
  double cost = kPieceCountCost * static_cast<double>(std::max(pieces.size(), t.size()) - common);
  for (std::size_t k = 0; k < common; ++k) {
    const StrokePiece& p = pieces[k];
    const StrokePieceTemplate& q = t[k];
    const double ds = wrap_deg(p.start_direction_deg - q.start_direction_deg) / q.start_tolerance_deg;
    const double de = wrap_deg(p.end_direction_deg - q.end_direction_deg) / q.end_tolerance_deg;
    cost += 0.5 * (ds * ds + de * de);
    const double fraction = total > 0.0 ? p.length / total : 0.0;
    if (q.hook && fraction > kHookFraction) cost += std::pow((fraction - kHookFraction) / kFractionScale, 2);
    if (p.length < q.min_length) cost += std::pow((q.min_length - p.length) / kLengthScale, 2);
    if (p.length > q.max_length) cost += std::pow((p.length - q.max_length) / kLengthScale, 2);
  }
  return cost;
}

// A short stroke falling slightly to the left is a 左点 (点2: 冖 1, 宀 2, 心 1, 忄 1), a short vertical
// (艹) or a short 撇; their directions overlap. The 左点 ends curling back toward the vertical, the
// others do not; of those, a stroke ending steeper than -112 degrees is a vertical. Measured over
// the corpus (docs/classification.md).
int resolve_short_vertical(const StrokePiece& p, int best_id) {
  constexpr int kS = 2, kP = 3, kD2 = 33;
  const bool in_zone = p.start_direction_deg > -118.0 && p.start_direction_deg < -85.0 && p.length < 280.0 &&
                       p.end_direction_deg > -125.0 && p.end_direction_deg < -95.0;
  if (!in_zone) return best_id;
  constexpr double kCurlDeg = 8.0;
  constexpr double kVerticalEndDeg = -112.0;
  if (p.exit_turn_deg >= kCurlDeg) return kD2;
  if (p.end_direction_deg > kVerticalEndDeg) return kS;
  return best_id == kD2 ? kP : best_id;
}

// A short stroke falling steeply to the right is a short vertical (the left side of a small 口) or a
// 点; a 点's end turns clockwise, the vertical stays straight. Measured over the corpus.
int resolve_dot_or_short_vertical(const StrokePiece& p, int best_id) {
  constexpr int kS = 2, kD = 4;
  const bool in_zone = best_id == kS && p.start_direction_deg > -65.0 && p.start_direction_deg < -45.0 &&
                       p.end_direction_deg > -85.0 && p.end_direction_deg < -65.0 && p.length < 300.0;
  constexpr double kDotTurnDeg = -8.0;
  return in_zone && p.exit_turn_deg <= kDotTurnDeg ? kD : best_id;
}

// A Kai 横 ends with a press that bends its end down; a 提 flicks up straight; a flat 捺 turns up. Where
// their directions overlap (a 横 rising steeply, a 提 starting flat), the turn at the end decides. Measured
// over the corpus (docs/classification.md).
int resolve_horizontal_or_tick(const StrokePiece& p, int best_id) {
  constexpr int kH = 1, kT = 6;
  if (p.start_direction_deg <= -10.0 || p.start_direction_deg >= 45.0) return best_id;
  constexpr double kPressDeg = -8.0;
  constexpr double kStraightDeg = 5.0;
  constexpr double kRisingEndDeg = 17.0;
  if (best_id == kT && p.exit_turn_deg <= kPressDeg) return kH;
  if (best_id == kH && std::abs(p.exit_turn_deg) < kStraightDeg && p.end_direction_deg >= kRisingEndDeg)
    return kT;
  // A long flat stroke whose end turns up is the flat 捺 (平捺, 之 3, 辶's last): the 横's end turns down.
  constexpr int kTN = 37;
  constexpr double kFlatNaLength = 500.0;
  constexpr double kFlatNaTurnDeg = 10.0;
  if (best_id == kH && p.length >= kFlatNaLength && p.exit_turn_deg >= kFlatNaTurnDeg) return kTN;
  return best_id;
}

}  // namespace

int classify_pieces(std::span<const StrokePiece> all_pieces) {
  if (all_pieces.empty()) throw InvalidArgument("classify_pieces: no pieces");
  // No typical stroke starts with a short piece going down-right before turning: that is the brush's
  // entry (the press before a 撇 or a vertical), not part of the stroke's shape.
  std::span<const StrokePiece> pieces = all_pieces;
  double whole = 0.0;
  for (const auto& p : all_pieces) whole += p.length;
  const StrokePiece& first = all_pieces.front();
  constexpr double kEntryFraction = 0.35;
  constexpr double kEntryLength = 120.0;
  if (pieces.size() > 1 && first.length < kEntryFraction * whole && first.length < kEntryLength &&
      first.start_direction_deg > -85.0 && first.start_direction_deg < -5.0) {
    pieces = pieces.subspan(1);
  }
  double total = 0.0;
  for (const auto& p : pieces) total += p.length;

  int best_id = 1;
  double best_cost = std::numeric_limits<double>::infinity();
  const auto consider = [&](int id, std::span<const StrokePieceTemplate> t, double extra) {
    const double cost = extra + prior_cost(id) + template_cost(pieces, total, t);
    if (cost < best_cost) {
      best_cost = cost;
      best_id = id;
    }
  };
  for (const TypicalStroke& t : typical_strokes()) consider(t.id, t.pieces, 0.0);
  for (const ObservedForm& f : kObservedForms)
    consider(f.id, std::span(f.pieces.data(), f.count), f.extra_cost);
  if (pieces.size() != 1) return best_id;
  const StrokePiece& only = pieces.front();
  return resolve_horizontal_or_tick(
      only, resolve_dot_or_short_vertical(only, resolve_short_vertical(only, best_id)));
}

Character fit_character(char32_t code_point, const std::vector<std::vector<Vec2>>& medians,
                        std::string source, const FitOptions& options) {
  Character character;
  character.code_point = code_point;
  character.source = std::move(source);
  character.strokes.reserve(medians.size());
  for (const auto& median : medians) character.strokes.push_back(fit_stroke(median, options).stroke);
  return character;
}

}  // namespace calligraphy
