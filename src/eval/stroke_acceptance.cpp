#include "eval/stroke_acceptance.hpp"

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>

#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy {

std::vector<char32_t> random_characters(const CharacterLibrary& library, std::size_t count,
                                        std::uint64_t seed, const std::vector<char32_t>& excluded) {
  const std::set<char32_t> left_out(excluded.begin(), excluded.end());
  std::vector<char32_t> pool;
  for (char32_t c : library.characters()) {
    if (left_out.count(c) == 0) pool.push_back(c);
  }
  std::mt19937_64 random(seed);
  std::shuffle(pool.begin(), pool.end(), random);
  if (pool.size() > count) pool.resize(count);
  return pool;
}

std::vector<KindAcceptance> empty_kind_table() {
  std::vector<KindAcceptance> kinds;
  for (TraceKind kind : kTraceKinds) {
    KindAcceptance k;
    k.kind = kind;
    kinds.push_back(k);
  }
  return kinds;
}

void add_kind_verdicts(std::vector<KindAcceptance>& kinds, const PlacedCharacter& character,
                       const PlacedCharacter& source, std::size_t stroke, std::mt19937_64& random,
                       double start_radius_m, const StrokeAcceptance& acceptance) {
  for (KindAcceptance& k : kinds) {
    if (!trace_applies(source, stroke, k.kind)) continue;
    // A kind added after the first thirteen draws from a copy of the generator, so that the other kinds'
    // paths stay the ones they were before it came.
    std::mt19937_64 copy = random;
    const bool added_later = k.kind == TraceKind::shifted_8mm;
    const std::vector<Vec2> path = person_trace(source, stroke, k.kind, added_later ? copy : random);
    const StrokeMatch match = match_stroke(character, stroke, path, start_radius_m, acceptance);
    ++k.paths;
    if (match.accepted) ++k.accepted;
    ++k.by_refusal[static_cast<std::size_t>(match.refusal)];
    if (match.accepted != is_positive(k.kind) && k.examples.size() < 5) {
      k.examples.push_back(encode_utf8(character.code_point) + " stroke " + std::to_string(stroke + 1) +
                           (match.accepted ? "" : std::string(" (") + to_string(match.refusal) + ")"));
    }
  }
}

AcceptanceMeasurement measure_acceptance(const CharacterLibrary& library,
                                         const std::vector<char32_t>& characters, std::uint64_t seed,
                                         const StrokeAcceptance& acceptance) {
  AcceptanceMeasurement m;
  m.characters = characters;
  m.seed = seed;
  m.kinds = empty_kind_table();
  SceneLayout layout;
  for (std::size_t c = 0; c < characters.size(); ++c) {
    const Scene scene = Scene::lay_out({library.load(characters[c])}, layout);
    const PlacedCharacter& character = scene.characters.front();
    // One generator per character: a character's paths do not depend on which others were drawn.
    std::mt19937_64 random(seed * 0x9e3779b97f4a7c15ULL + characters[c]);
    for (std::size_t s = 0; s < character.strokes.size(); ++s) {
      ++m.strokes;
      add_kind_verdicts(m.kinds, character, character, s, random, layout.start_radius_m, acceptance);
    }
  }
  return m;
}

std::string kind_table_markdown(const std::vector<KindAcceptance>& kinds) {
  std::string out =
      "| kind | label | paths | accepted | too short | backwards | wrong place | wrong stroke | wrong order "
      "| "
      "verdict right |\n| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  char line[400];
  for (const KindAcceptance& k : kinds) {
    const bool positive = is_positive(k.kind);
    const std::size_t right = positive ? k.accepted : k.paths - k.accepted;
    const auto& r = k.by_refusal;
    std::snprintf(line, sizeof line, "| %s | %s | %zu | %zu | %zu | %zu | %zu | %zu | %zu | %.2f %% |\n",
                  to_string(k.kind), positive ? "positive" : "negative", k.paths, k.accepted, r[1], r[2],
                  r[3], r[4], r[5],
                  k.paths > 0 ? 100.0 * static_cast<double>(right) / static_cast<double>(k.paths) : 0.0);
    out += line;
  }
  std::string examples;
  for (const KindAcceptance& k : kinds) {
    if (k.examples.empty()) continue;
    examples += "- " + std::string(to_string(k.kind)) + (is_positive(k.kind) ? " refused: " : " accepted: ");
    for (std::size_t i = 0; i < k.examples.size(); ++i) examples += (i > 0 ? ", " : "") + k.examples[i];
    examples += "\n";
  }
  if (!examples.empty()) out += "\nWrong verdicts, first examples:\n\n" + examples;
  return out;
}

std::string acceptance_markdown(const AcceptanceMeasurement& m, const std::string& invocation) {
  std::string out = "Made by `" + invocation + "`: " + std::to_string(m.characters.size()) + " characters, " +
                    std::to_string(m.strokes) + " strokes, one path of each kind per stroke.\n\n";
  out += kind_table_markdown(m.kinds);
  return out;
}

}  // namespace calligraphy
