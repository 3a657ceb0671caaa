#include "eval/other_hand.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/stroke_outline.hpp"
#include "calligraphy/sim/person_traces.hpp"

namespace calligraphy {
namespace {

// Points per stroke of the alignment: enough to follow a hook, the same for every stroke so that each
// stroke weighs alike whatever its length.
constexpr int kAlignmentPoints = 32;
// Points per stroke of the form test's discrete Frechet distance.
constexpr int kFormPoints = 64;
std::vector<Vec2> resampled(const std::vector<Vec2>& line, int points) {
  std::vector<double> arc(line.size(), 0.0);
  for (std::size_t i = 1; i < line.size(); ++i) arc[i] = arc[i - 1] + (line[i] - line[i - 1]).norm();
  std::vector<Vec2> out;
  std::size_t k = 1;
  for (int i = 0; i < points; ++i) {
    const double s = arc.back() * i / (points - 1);
    while (k + 1 < line.size() && arc[k] < s) ++k;
    const double span = arc[k] - arc[k - 1];
    const double t = span > 0.0 ? std::clamp((s - arc[k - 1]) / span, 0.0, 1.0) : 0.0;
    out.push_back(line[k - 1] + t * (line[k] - line[k - 1]));
  }
  return out;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw DataError(file.string() + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string percent(std::size_t part, std::size_t whole) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%",
                whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0);
  return text;
}

}  // namespace

std::filesystem::path kanjivg_file(const std::filesystem::path& folder, char32_t code_point) {
  char name[16];
  std::snprintf(name, sizeof name, "%05x.svg", static_cast<unsigned>(code_point));
  return folder / name;
}

std::vector<std::vector<Vec2>> read_kanjivg_strokes(const std::filesystem::path& file) {
  const std::string text = read_text(file);
  std::vector<std::vector<Vec2>> strokes;
  for (std::size_t at = text.find("<path"); at != std::string::npos; at = text.find("<path", at + 1)) {
    const std::size_t close = text.find('>', at);
    const std::size_t d = text.find(" d=\"", at);
    if (close == std::string::npos || d == std::string::npos || d > close) {
      throw DataError(file.string() + ": a <path> without d=\"...\"");
    }
    const std::size_t end = text.find('"', d + 4);
    if (end == std::string::npos) throw DataError(file.string() + ": an unterminated d=\"...\"");
    try {
      std::vector<std::vector<Vec2>> lines =
          parse_svg_polylines(std::string_view(text).substr(d + 4, end - d - 4), 0.05);
      std::vector<Vec2> stroke;
      for (const std::vector<Vec2>& line : lines) stroke.insert(stroke.end(), line.begin(), line.end());
      strokes.push_back(std::move(stroke));
    } catch (const DataError& error) {
      throw DataError(file.string() + ": stroke " + std::to_string(strokes.size() + 1) + ": " + error.what());
    }
  }
  return strokes;
}

std::vector<std::vector<Vec2>> align_to_medians(const std::vector<std::vector<Vec2>>& strokes,
                                                const PlacedCharacter& character) {
  if (strokes.size() != character.strokes.size()) {
    throw InvalidArgument("align_to_medians: " + std::to_string(strokes.size()) +
                          " strokes for a character of " + std::to_string(character.strokes.size()));
  }
  // Least squares of q = s p + t over the paired points, p flipped to y up: s = sum (p - p0).(q - q0) /
  // sum |p - p0|^2, t = q0 - s p0 (ordinary least squares in the scale, the shift following).
  std::vector<Vec2> from;
  std::vector<Vec2> to;
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    if (strokes[i].size() < 2 || character.strokes[i].median_m.size() < 2) {
      throw InvalidArgument("align_to_medians: stroke " + std::to_string(i + 1) + " has no line");
    }
    for (const Vec2& p : resampled(strokes[i], kAlignmentPoints)) from.emplace_back(p.x(), -p.y());
    const std::vector<Vec2> q = resampled(character.strokes[i].median_m, kAlignmentPoints);
    to.insert(to.end(), q.begin(), q.end());
  }
  Vec2 p0 = Vec2::Zero();
  Vec2 q0 = Vec2::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    p0 += from[i];
    q0 += to[i];
  }
  p0 /= static_cast<double>(from.size());
  q0 /= static_cast<double>(to.size());
  double cross = 0.0;
  double spread = 0.0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    cross += (from[i] - p0).dot(to[i] - q0);
    spread += (from[i] - p0).squaredNorm();
  }
  const double scale = spread > 0.0 ? cross / spread : 0.0;
  std::vector<std::vector<Vec2>> out;
  for (const std::vector<Vec2>& stroke : strokes) {
    std::vector<Vec2> line;
    for (const Vec2& p : stroke) line.push_back(q0 + scale * (Vec2(p.x(), -p.y()) - p0));
    out.push_back(std::move(line));
  }
  return out;
}

double discrete_frechet_m(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  // Eiter & Mannila 1994, by dynamic programming over the two point sequences.
  std::vector<double> row(b.size());
  std::vector<double> previous(b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      const double d = (a[i] - b[j]).norm();
      if (i == 0 && j == 0) {
        row[j] = d;
      } else if (i == 0) {
        row[j] = std::max(row[j - 1], d);
      } else if (j == 0) {
        row[j] = std::max(previous[j], d);
      } else {
        row[j] = std::max(std::min({previous[j], previous[j - 1], row[j - 1]}), d);
      }
    }
    std::swap(row, previous);
  }
  return previous.back();
}

bool same_order_and_form(const std::vector<std::vector<Vec2>>& lines, const PlacedCharacter& character,
                         double form_tolerance_m) {
  // Mean distance between the resampled line and the resampled median, point by point.
  const auto distance = [](const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
    double sum = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]).norm();
    return sum / static_cast<double>(a.size());
  };
  std::vector<std::vector<Vec2>> medians;
  for (const PlacedStroke& stroke : character.strokes) {
    medians.push_back(resampled(stroke.median_m, kAlignmentPoints));
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::vector<Vec2> line = resampled(lines[i], kAlignmentPoints);
    const double own = distance(line, medians[i]);
    std::vector<Vec2> reversed(medians[i].rbegin(), medians[i].rend());
    if (distance(line, reversed) < own) return false;
    if (discrete_frechet_m(resampled(lines[i], kFormPoints),
                           resampled(character.strokes[i].median_m, kFormPoints)) > form_tolerance_m) {
      return false;
    }
    for (std::size_t j = 0; j < medians.size(); ++j) {
      if (j != i && distance(line, medians[j]) < own) return false;
    }
  }
  return true;
}

const char* to_string(KanjivgHalf half) noexcept {
  switch (half) {
    case KanjivgHalf::tuning:
      return "tuning";
    case KanjivgHalf::held_out:
      return "held-out";
    case KanjivgHalf::whole:
      return "whole";
  }
  return "?";
}

KanjivgHalf kanjivg_half_of(char32_t code_point) noexcept {
  // SplitMix64's finaliser (Steele, Lea & Flood 2014): every bit of the code point moves the low bit.
  std::uint64_t z = static_cast<std::uint64_t>(code_point) + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30U)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27U)) * 0x94d049bb133111ebULL;
  z ^= z >> 31U;
  return (z & 1U) == 0U ? KanjivgHalf::tuning : KanjivgHalf::held_out;
}

SharedCharacters draw_shared_characters(const CharacterLibrary& library, const std::filesystem::path& folder,
                                        std::size_t count, std::uint64_t seed,
                                        const std::vector<char32_t>& excluded, double form_tolerance_m,
                                        KanjivgHalf half) {
  const std::set<char32_t> left_out(excluded.begin(), excluded.end());
  SharedCharacters out;
  std::vector<char32_t> pool;
  for (char32_t c : library.characters()) {
    if (left_out.count(c) == 0 && (half == KanjivgHalf::whole || kanjivg_half_of(c) == half) &&
        std::filesystem::is_regular_file(kanjivg_file(folder, c)))
      pool.push_back(c);
  }
  out.with_file = pool.size();
  std::mt19937_64 random(seed);
  std::shuffle(pool.begin(), pool.end(), random);
  // Drawn in the shuffled order, kept when the stroke counts match: a uniform draw from the intersection.
  for (char32_t c : pool) {
    if (out.chosen.size() >= count) break;
    ++out.looked_at;
    std::vector<std::vector<Vec2>> strokes;
    try {
      strokes = read_kanjivg_strokes(kanjivg_file(folder, c));
    } catch (const DataError&) {
      continue;  // a file that does not parse is not in the intersection
    }
    const Character character = library.load(c);
    if (strokes.size() != character.strokes.size()) continue;
    ++out.same_count;
    const Scene scene = Scene::lay_out({character});
    const std::vector<std::vector<Vec2>> lines = align_to_medians(strokes, scene.characters.front());
    // The order alone: any form passes a tolerance as wide as the box.
    if (!same_order_and_form(lines, scene.characters.front(), std::numeric_limits<double>::infinity()))
      continue;
    ++out.same_order;
    if (same_order_and_form(lines, scene.characters.front(), form_tolerance_m)) {
      ++out.same_form;
      out.chosen.push_back(c);
    }
  }
  return out;
}

std::vector<char32_t> random_shared_characters(const CharacterLibrary& library,
                                               const std::filesystem::path& folder, std::size_t count,
                                               std::uint64_t seed, const std::vector<char32_t>& excluded,
                                               double form_tolerance_m, KanjivgHalf half) {
  return draw_shared_characters(library, folder, count, seed, excluded, form_tolerance_m, half).chosen;
}

OtherHandMeasurement measure_other_hand(const CharacterLibrary& library, const std::filesystem::path& folder,
                                        const std::vector<char32_t>& characters, std::uint64_t seed,
                                        std::uint32_t assist_after_misses,
                                        const StrokeAcceptance& acceptance) {
  OtherHandMeasurement m;
  m.characters = characters;
  m.seed = seed;
  m.assist_after_misses = assist_after_misses;
  m.kinds = empty_kind_table();
  const SceneLayout layout;
  for (char32_t code_point : characters) {
    const Scene scene = Scene::lay_out({library.load(code_point)}, layout);
    const PlacedCharacter& character = scene.characters.front();
    const std::vector<std::vector<Vec2>> lines =
        align_to_medians(read_kanjivg_strokes(kanjivg_file(folder, code_point)), character);
    PlacedCharacter other_hand = character;
    for (std::size_t s = 0; s < lines.size(); ++s) other_hand.strokes[s].median_m = lines[s];
    std::mt19937_64 random(seed * 0x9e3779b97f4a7c15ULL + code_point);
    bool first_attempts = true;
    bool unassisted = true;
    bool completed = true;
    for (std::size_t s = 0; s < character.strokes.size(); ++s) {
      ++m.strokes;
      std::uint32_t misses = 0;
      bool accepted = false;
      // Attempts until accepted, credited assisted after assist_after_misses misses (or, with 0, given up
      // after as many attempts as the default would allow: a person does not write for ever).
      const std::uint32_t attempts = assist_after_misses > 0 ? assist_after_misses : 5;
      while (!accepted && misses < attempts) {
        const std::vector<Vec2> path = pointer_trace(lines[s], random);
        const StrokeMatch match = match_stroke(character, s, path, layout.start_radius_m, acceptance);
        accepted = match.accepted;
        if (accepted) break;
        if (misses == 0 && m.refused.size() < 8) {
          m.refused.push_back(encode_utf8(code_point) + " stroke " + std::to_string(s + 1) + " (" +
                              to_string(match.refusal) + ")");
        }
        ++misses;
      }
      if (accepted && misses == 0) ++m.strokes_first_attempt;
      if (misses > 0) first_attempts = false;
      if (accepted) {
        ++m.strokes_unassisted;
      } else {
        unassisted = false;
        if (assist_after_misses > 0) {
          ++m.strokes_assisted;
        } else {
          completed = false;
        }
      }
      add_kind_verdicts(m.kinds, character, other_hand, s, random, layout.start_radius_m, acceptance);
    }
    if (first_attempts) ++m.characters_first_attempt;
    if (unassisted) ++m.characters_unassisted;
    if (completed) ++m.characters_completed;
  }
  return m;
}

std::string other_hand_markdown(const OtherHandMeasurement& m, const std::string& invocation) {
  const std::size_t n = m.characters.size();
  std::string out =
      "Made by `" + invocation + "`: " + std::to_string(n) + " characters, " + std::to_string(m.strokes) +
      " strokes, each written along its KanjiVG line by a position-only pen; a refused stroke "
      "is written again until " +
      (m.assist_after_misses > 0 ? "it has been refused " + std::to_string(m.assist_after_misses) +
                                       " times (`assist_after_misses`), when it is credited assisted.\n\n"
                                 : "it has been refused 5 times (no assisted credit).\n\n");
  if (m.draw.with_file > 0) {  // said when the draw's counts were kept
    const SharedCharacters& d = m.draw;
    char text[400];
    std::snprintf(
        text, sizeof text,
        "Drawn from the %s half (a hash of the code point; the rule is tuned on the other) with the "
        "same form within %g mm: of the %zu characters of the half that KanjiVG has, %zu looked at, "
        "%zu with as many strokes, %zu of those in the same order, %zu of those in the same form.\n\n",
        to_string(m.half), m.form_tolerance_m * 1000.0, d.with_file, d.looked_at, d.same_count, d.same_order,
        d.same_form);
    if (m.half != KanjivgHalf::held_out) {
      std::snprintf(
          text, sizeof text,
          "Drawn from the %s half (a hash of the code point) with the same form within %g mm: of the "
          "%zu characters of the half that KanjiVG has, %zu looked at, %zu with as many strokes, "
          "%zu of those in the same order, %zu of those in the same form.\n\n",
          to_string(m.half), m.form_tolerance_m * 1000.0, d.with_file, d.looked_at, d.same_count,
          d.same_order, d.same_form);
    }
    out += text;
  }
  out += "| measure | count | of | share |\n| --- | ---: | ---: | ---: |\n";
  const auto row = [&out](const std::string& what, std::size_t part, std::size_t whole) {
    out += "| " + what + " | " + std::to_string(part) + " | " + std::to_string(whole) + " | " +
           percent(part, whole) + " |\n";
  };
  row("strokes accepted at the first attempt", m.strokes_first_attempt, m.strokes);
  row("strokes accepted without assistance", m.strokes_unassisted, m.strokes);
  row("strokes credited assisted", m.strokes_assisted, m.strokes);
  row("characters with every stroke accepted at the first attempt", m.characters_first_attempt, n);
  row("characters completed without assistance", m.characters_unassisted, n);
  row("characters completed with assistance", m.characters_completed, n);
  if (!m.refused.empty()) {
    out += "\nStrokes refused at the first attempt, first examples: ";
    for (std::size_t i = 0; i < m.refused.size(); ++i) out += (i > 0 ? ", " : "") + m.refused[i];
    out += "\n";
  }
  out += "\nEvery kind of labelled path made from the aligned KanjiVG lines instead of the medians:\n\n";
  out += kind_table_markdown(m.kinds);
  return out;
}

}  // namespace calligraphy
