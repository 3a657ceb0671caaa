#include "calligraphy/sim/person_traces.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

constexpr double kMm = 1e-3;
constexpr double kStep_m = 0.2 * kMm;  // spacing of the dense paths [m]

using Path = std::vector<Vec2>;

double uniform(std::mt19937_64& random, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(random);
}

std::vector<double> arcs(const Path& path) {
  std::vector<double> arc(path.size(), 0.0);
  for (std::size_t i = 1; i < path.size(); ++i) arc[i] = arc[i - 1] + (path[i] - path[i - 1]).norm();
  return arc;
}

// The point at arc `s` of `path` (clamped to its ends).
Vec2 at_arc(const Path& path, const std::vector<double>& arc, double s) {
  if (s <= 0.0) return path.front();
  if (s >= arc.back()) return path.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin());
  const double span = arc[k] - arc[k - 1];
  const double t = span > 0.0 ? (s - arc[k - 1]) / span : 0.0;
  return path[k - 1] + t * (path[k] - path[k - 1]);
}

// `path` between arcs `from` and `to`, resampled every kStep_m.
Path resampled(const Path& path, double from, double to) {
  const std::vector<double> arc = arcs(path);
  Path out;
  const int n = std::max(1, static_cast<int>(std::ceil((to - from) / kStep_m)));
  for (int i = 0; i <= n; ++i) out.push_back(at_arc(path, arc, from + (to - from) * i / n));
  return out;
}

Vec2 unit(const Vec2& v) { return v.norm() > 0.0 ? Vec2(v / v.norm()) : Vec2::UnitX(); }

// Direction of the path over its first or last `reach` of arc.
Vec2 end_direction(const Path& path, bool at_start, double reach) {
  const std::vector<double> arc = arcs(path);
  if (at_start) return unit(at_arc(path, arc, reach) - path.front());
  return unit(path.back() - at_arc(path, arc, arc.back() - reach));
}

// Each corner of the median (a vertex turning by more than 35 degrees) replaced by a point `overshoot`
// past it along the incoming direction: the pen carries on before it turns.
Path overshoot_corners(const Path& median, double overshoot) {
  Path out{median.front()};
  for (std::size_t k = 1; k + 1 < median.size(); ++k) {
    const Vec2 in = unit(median[k] - median[k - 1]);
    const Vec2 next = unit(median[k + 1] - median[k]);
    const bool corner = in.dot(next) < std::cos(35.0 * std::numbers::pi / 180.0);
    out.push_back(corner ? Vec2(median[k] + overshoot * in) : median[k]);
  }
  out.push_back(median.back());
  return out;
}

// Moving average over `window` of arc: rounds corners inside as a hand does.
Path smoothed(const Path& dense, double window) {
  const int half = static_cast<int>(std::round(window / kStep_m / 2.0));
  if (half < 1) return dense;
  Path out(dense.size());
  const int n = static_cast<int>(dense.size());
  for (int i = 0; i < n; ++i) {
    const int h = std::min({half, i, n - 1 - i});  // the ends stay where they are
    Vec2 sum = Vec2::Zero();
    for (int j = i - h; j <= i + h; ++j) sum += dense[static_cast<std::size_t>(j)];
    out[static_cast<std::size_t>(i)] = sum / (2.0 * h + 1.0);
  }
  return out;
}

struct HumanStyle {
  double start_in = 0.0;   // arc skipped at the start [m] (< 0: starts before it)
  double end_delta = 0.0;  // < 0: lifted short by this much of arc; > 0: carried past [m]
  double smoothing = 0.0;  // moving-average window [m]
  double overshoot = 0.0;  // corner overshoot [m]
  double offset = 0.0, offset_angle = 0.0, rotation = 0.0, scale = 1.0;
  double drift = 0.0, drift_wavelength = 1.0, tremor = 0.0, tremor_wavelength = 1.0, noise = 0.0;
};

// People's copies of a stroke (docs/stroke-acceptance.md): the copy is offset by up to 2.2 mm, turned by
// up to 4 degrees and scaled by up to 5 %, drifts 0.2-1 mm across over 15-40 mm, trembles 0.03-0.15 mm at
// 9 Hz (4-10 mm of arc at 40-100 mm/s), starts within 1 mm of the start and ends 2 mm short to 2.5 mm
// past. That puts the discrete Frechet distance to the median at about what another hand's strokes show
// (median 2.3 mm, 95th percentile 3.4 mm in a 60 mm box), with ends within 3.5 mm.
HumanStyle human_style(std::mt19937_64& random, double length) {
  HumanStyle s;
  s.start_in = std::min(uniform(random, -1.0, 1.0) * kMm, 0.08 * length);
  s.end_delta = std::max(uniform(random, -2.0, 2.5) * kMm, -0.12 * length);
  s.smoothing = uniform(random, 0.5, 2.0) * kMm;
  s.offset = uniform(random, 0.0, 2.2) * kMm;
  s.offset_angle = uniform(random, 0.0, 2.0 * std::numbers::pi);
  s.rotation = uniform(random, -4.0, 4.0) * std::numbers::pi / 180.0;
  s.scale = uniform(random, 0.95, 1.05);
  s.drift = uniform(random, 0.2, 1.0) * kMm;
  s.drift_wavelength = uniform(random, 15.0, 40.0) * kMm;
  s.tremor = uniform(random, 0.03, 0.15) * kMm;
  s.tremor_wavelength = uniform(random, 4.0, 10.0) * kMm;
  s.noise = 0.02 * kMm;
  return s;
}

double length_of(const Path& path) { return arcs(path).back(); }

Path human_path(const Path& median, const HumanStyle& style, std::mt19937_64& random) {
  const Path base = style.overshoot > 0.0 ? overshoot_corners(median, style.overshoot) : median;
  const double length = length_of(base);
  Path dense = smoothed(resampled(base, 0.0, length), style.smoothing);
  // The ends: skip or extend the start, stop short of or carry past the end along the end's direction.
  const Vec2 start_direction = end_direction(dense, true, std::min(1.5 * kMm, 0.3 * length));
  const Vec2 finish_direction = end_direction(dense, false, std::min(1.5 * kMm, 0.3 * length));
  const double from = std::max(0.0, style.start_in);
  const double to = length + std::min(0.0, style.end_delta);
  Path path = resampled(dense, from, std::max(from, to));
  if (style.start_in < 0.0) {
    const Vec2 first = path.front();
    const int n = static_cast<int>(std::ceil(-style.start_in / kStep_m));
    for (int i = 1; i <= n; ++i)
      path.insert(path.begin(), first - start_direction * (-style.start_in * i / n));
  }
  if (style.end_delta > 0.0) {
    const Vec2 last = path.back();
    const int n = static_cast<int>(std::ceil(style.end_delta / kStep_m));
    for (int i = 1; i <= n; ++i) path.push_back(last + finish_direction * (style.end_delta * i / n));
  }
  // The copy: turned and scaled about its centre, then offset.
  Vec2 centre = Vec2::Zero();
  for (const Vec2& p : path) centre += p;
  centre /= static_cast<double>(path.size());
  const Eigen::Rotation2Dd turn(style.rotation);
  const Vec2 offset = style.offset * Vec2(std::cos(style.offset_angle), std::sin(style.offset_angle));
  // Drift, tremor and noise across the path.
  const std::vector<double> arc = arcs(path);
  const double drift_phase = uniform(random, 0.0, 2.0 * std::numbers::pi);
  const double tremor_phase = uniform(random, 0.0, 2.0 * std::numbers::pi);
  std::normal_distribution<double> noise(0.0, style.noise);
  Path out(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Vec2 along = unit(path[std::min(i + 1, path.size() - 1)] - path[i > 0 ? i - 1 : 0]);
    const Vec2 across(-along.y(), along.x());
    const double lateral =
        style.drift * std::sin(2.0 * std::numbers::pi * arc[i] / style.drift_wavelength + drift_phase) +
        style.tremor * std::sin(2.0 * std::numbers::pi * arc[i] / style.tremor_wavelength + tremor_phase) +
        noise(random);
    out[i] = centre + style.scale * (turn * (path[i] - centre)) + offset + lateral * across;
  }
  return out;
}

// `path` written by a mouse: moved along it with a minimum-jerk profile (Flash & Hogan 1985) at 60-110
// mm/s, sampled at 60 Hz, on 0.15 mm pixels (a 60 mm character on 400 pixels).
Path pointer_samples(const Path& path, std::mt19937_64& random) {
  const std::vector<double> arc = arcs(path);
  const double speed = uniform(random, 0.06, 0.11);
  const double duration = std::max(arc.back() / speed, 1.0 / 60.0);
  const double pixel = 0.15 * kMm;
  Path out;
  for (double t = 0.0;; t += 1.0 / 60.0) {
    const double tau = std::min(1.0, t / duration);
    const double s = arc.back() * (10 * std::pow(tau, 3) - 15 * std::pow(tau, 4) + 6 * std::pow(tau, 5));
    const Vec2 p = at_arc(path, arc, s);
    out.push_back(Vec2(std::round(p.x() / pixel) * pixel, std::round(p.y() / pixel) * pixel));
    if (tau >= 1.0) break;
  }
  return out;
}

// How far short of the end a mouse is released: 0.2-1.5 mm, at most 12 % of the stroke.
double pointer_release_short(std::mt19937_64& random, double length) {
  return std::min(uniform(random, 0.2, 1.5) * kMm, 0.12 * length);
}

// A mouse: the `human` path with more wobble, written by pointer_samples, released short.
Path pointer_path(const Path& median, std::mt19937_64& random) {
  HumanStyle style = human_style(random, length_of(median));
  style.end_delta = -pointer_release_short(random, length_of(median));
  style.drift = uniform(random, 0.3, 0.9) * kMm;
  return pointer_samples(human_path(median, style, random), random);
}

Path scribble_path(const PlacedCharacter& character, const Path& median, std::mt19937_64& random) {
  const double angle0 = uniform(random, 0.0, 2.0 * std::numbers::pi);
  Vec2 p = median.front() + uniform(random, 0.0, 1.5) * kMm * Vec2(std::cos(angle0), std::sin(angle0));
  Path corners{p};
  for (int i = 0; i < 8; ++i) {
    const double angle = uniform(random, 0.0, 2.0 * std::numbers::pi);
    p += uniform(random, 4.0, 12.0) * kMm * Vec2(std::cos(angle), std::sin(angle));
    p = p.cwiseMax(character.bounding_box.min()).cwiseMin(character.bounding_box.max());
    corners.push_back(p);
  }
  return resampled(corners, 0.0, length_of(corners));
}

const Path& median_of(const PlacedCharacter& character, std::size_t stroke) {
  const Path& median = character.strokes[stroke].median_m;
  if (median.size() < 2) {
    throw InvalidArgument("person_trace: stroke " + std::to_string(stroke) + " has no median");
  }
  return median;
}

}  // namespace

bool is_positive(TraceKind kind) noexcept {
  switch (kind) {
    case TraceKind::median:
    case TraceKind::human:
    case TraceKind::corners_cut:
    case TraceKind::corners_overshot:
    case TraceKind::ends_short:
    case TraceKind::ends_past:
    case TraceKind::pointer:
      return true;
    default:
      return false;
  }
}

const char* to_string(TraceKind kind) noexcept {
  switch (kind) {
    case TraceKind::median:
      return "median";
    case TraceKind::human:
      return "human";
    case TraceKind::corners_cut:
      return "corners_cut";
    case TraceKind::corners_overshot:
      return "corners_overshot";
    case TraceKind::ends_short:
      return "ends_short";
    case TraceKind::ends_past:
      return "ends_past";
    case TraceKind::pointer:
      return "pointer";
    case TraceKind::reversed:
      return "reversed";
    case TraceKind::half:
      return "half";
    case TraceKind::shifted:
      return "shifted";
    case TraceKind::other_stroke:
      return "other_stroke";
    case TraceKind::swapped_order:
      return "swapped_order";
    case TraceKind::scribble:
      return "scribble";
    case TraceKind::shifted_8mm:
      return "shifted_8mm";
  }
  return "?";
}

bool trace_applies(const PlacedCharacter& character, std::size_t stroke, TraceKind kind) noexcept {
  if (stroke >= character.strokes.size()) return false;
  if (kind == TraceKind::other_stroke) return character.strokes.size() >= 2;
  if (kind == TraceKind::swapped_order) return stroke + 1 < character.strokes.size();
  return true;
}

std::vector<Vec2> person_trace(const PlacedCharacter& character, std::size_t stroke, TraceKind kind,
                               std::mt19937_64& random) {
  if (!trace_applies(character, stroke, kind)) {
    throw InvalidArgument(std::string("person_trace: '") + to_string(kind) + "' does not apply to stroke " +
                          std::to_string(stroke) + " of a character with " +
                          std::to_string(character.strokes.size()) + " strokes");
  }
  const Path& median = median_of(character, stroke);
  const double length = length_of(median);
  HumanStyle style = human_style(random, length);
  switch (kind) {
    case TraceKind::median:
      return median;
    case TraceKind::human:
    case TraceKind::reversed:
      break;
    case TraceKind::half:  // half of the stroke itself: from its start, or to its end
      style.start_in = 0.0;
      style.end_delta = 0.0;
      break;
    case TraceKind::shifted:  // the shift is the offset of the copy
    case TraceKind::shifted_8mm:
      style.offset = 0.0;
      break;
    case TraceKind::corners_cut:
      style.smoothing = uniform(random, 2.0, 5.0) * kMm;
      break;
    case TraceKind::corners_overshot:
      style.overshoot = uniform(random, 1.0, 2.5) * kMm;
      break;
    case TraceKind::ends_short:
      style.end_delta = -std::min(uniform(random, 0.5, 3.0) * kMm, 0.15 * length);
      break;
    case TraceKind::ends_past:
      style.end_delta = uniform(random, 0.5, 4.0) * kMm;
      break;
    case TraceKind::pointer:
      return pointer_path(median, random);
    case TraceKind::other_stroke: {
      std::size_t other = std::uniform_int_distribution<std::size_t>(0, character.strokes.size() - 2)(random);
      if (other >= stroke) ++other;
      const Path& m = median_of(character, other);
      return human_path(m, human_style(random, length_of(m)), random);
    }
    case TraceKind::swapped_order: {
      const Path& m = median_of(character, stroke + 1);
      return human_path(m, human_style(random, length_of(m)), random);
    }
    case TraceKind::scribble:
      return scribble_path(character, median, random);
  }
  Path path = human_path(median, style, random);
  if (kind == TraceKind::reversed) std::reverse(path.begin(), path.end());
  if (kind == TraceKind::half) {
    const bool first = std::bernoulli_distribution(0.5)(random);
    const std::size_t middle = path.size() / 2;
    path = first ? Path(path.begin(), path.begin() + static_cast<long>(middle) + 1)
                 : Path(path.begin() + static_cast<long>(middle), path.end());
  }
  if (kind == TraceKind::shifted || kind == TraceKind::shifted_8mm) {
    // Every point moved the same distance across the stroke (along the normal over +-1 mm of the path): a
    // parallel copy, so that no part of it lies on the stroke (a translation would move an L-shaped
    // stroke's legs along themselves).
    const double shift =
        kind == TraceKind::shifted_8mm
            ? (std::bernoulli_distribution(0.5)(random) ? 1.0 : -1.0) * 8.0 * kMm
            : (std::bernoulli_distribution(0.5)(random) ? 1.0 : -1.0) * uniform(random, 4.0, 8.0) * kMm;
    const std::size_t reach = 5;
    Path moved(path.size());
    for (std::size_t i = 0; i < path.size(); ++i) {
      const Vec2 along = unit(path[std::min(i + reach, path.size() - 1)] - path[i >= reach ? i - reach : 0]);
      moved[i] = path[i] + shift * Vec2(-along.y(), along.x());
    }
    path = moved;
  }
  return path;
}

std::vector<Vec2> pointer_trace(const std::vector<Vec2>& line_m, std::mt19937_64& random) {
  if (line_m.size() < 2 || !(length_of(line_m) > 0.0)) {
    throw InvalidArgument("pointer_trace: the line has fewer than 2 distinct points");
  }
  const double length = length_of(line_m);
  return pointer_samples(resampled(line_m, 0.0, length - pointer_release_short(random, length)), random);
}

}  // namespace calligraphy
