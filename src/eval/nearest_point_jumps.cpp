#include "eval/nearest_point_jumps.hpp"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"
#include "eval/nearest_point_report.hpp"
#include "eval/report_numbers.hpp"

namespace calligraphy::cli {
namespace {

// A way to find the foot point tick after tick. `reset` is called at the start of each WS run and
// whenever the active element changes.
struct FootFinder {
  std::string name;
  NearestPointOptions options;  // for the stateless methods
  bool tracked = false;         // NearestPointTracker with its default options
};

struct Tally {
  std::vector<std::string> where;
  std::size_t strokes = 0;
  std::size_t ws_ticks = 0;
  std::size_t jumps = 0;
  std::size_t jumps_at_switch = 0;
  std::size_t strokes_with_jump = 0;
  double max_jump_m = 0.0;
};

// Replays the WS ticks of one trace through `finder`, adding to `tally`. A stroke is counted once
// per trial, over all its attempts; the foot is compared between consecutive ticks of one WS run.
void replay(const PlacedCharacter& character, std::uint64_t seed, const std::vector<TrialSample>& trace,
            const FootFinder& finder, double threshold_m, Tally& tally) {
  std::vector<std::size_t> jumps_of_stroke(character.strokes.size(), 0);
  std::vector<bool> stroke_seen(character.strokes.size(), false);
  NearestPointTracker tracker;
  bool in_run = false;
  std::size_t run_stroke = 0;
  std::size_t run_element = 0;
  Vec2 previous_foot = Vec2::Zero();
  for (const TrialSample& sample : trace) {
    if (sample.state != InteractionState::writing || sample.stroke >= character.strokes.size()) {
      in_run = false;
      continue;
    }
    const PlacedStroke& stroke = character.strokes[sample.stroke];
    if (sample.element >= stroke.elements.size()) {
      in_run = false;
      continue;
    }
    const StrokeElement& element = stroke.elements[sample.element];
    const Vec2 tip = sample.position_m.head<2>();
    const bool same_run = in_run && run_stroke == sample.stroke;
    if (!same_run || run_element != sample.element) tracker.reset();
    const Vec2 foot =
        finder.tracked ? tracker.update(element, tip).foot : nearest_point(element, tip, finder.options).foot;
    if (same_run) {
      const double move = (foot - previous_foot).norm();
      tally.max_jump_m = std::max(tally.max_jump_m, move);
      if (move > threshold_m) {
        ++tally.jumps;
        if (run_element != sample.element) ++tally.jumps_at_switch;
        ++jumps_of_stroke[sample.stroke];
      }
    }
    ++tally.ws_ticks;
    stroke_seen[sample.stroke] = true;
    in_run = true;
    run_stroke = sample.stroke;
    run_element = sample.element;
    previous_foot = foot;
  }
  for (std::size_t s = 0; s < character.strokes.size(); ++s) {
    if (!stroke_seen[s]) continue;
    ++tally.strokes;
    if (jumps_of_stroke[s] == 0) continue;
    ++tally.strokes_with_jump;
    tally.where.push_back(encode_utf8(character.code_point) + " stroke " + std::to_string(s + 1) + " seed " +
                          std::to_string(seed));
  }
}

}  // namespace

JumpMeasurement measure_foot_jumps(const CharacterLibrary& library, const JumpSettings& settings) {
  JumpMeasurement measurement;
  measurement.settings = settings;
  std::u32string characters = settings.characters;
  if (characters.empty()) {
    for (const char32_t c : CharacterLibrary::embedded().characters()) characters.push_back(c);
  }
  measurement.characters = characters.size();

  std::vector<FootFinder> finders(4);
  finders[0].name = "exact";
  finders[1].name = "tracker";
  finders[1].tracked = true;
  finders[2].name = "newton";
  finders[2].options.method = NearestPointMethod::newton;
  finders[3].name = "subdivision";
  finders[3].options.method = NearestPointMethod::subdivision;
  finders[3].options.tolerance = settings.subdivision_tolerance_m;

  std::vector<Scene> scenes;
  for (const char32_t c : characters) scenes.push_back(Scene::lay_out({library.load(c)}));
  for (const bool guidance : settings.guidance) {
    std::vector<Tally> tallies(finders.size());
    for (const Scene& scene : scenes) {
      for (const std::uint64_t seed : settings.seeds) {
        TrialOptions options;  // 1 kHz, simulated Phantom Desktop, novice writer; the renderer uses exact
        options.force.guidance = guidance;
        SimulationOptions simulation;
        simulation.seed = seed;
        const TrialResult trial = run_simulated_trial(scene, options, simulation);
        ++measurement.trials;
        if (trial.metrics.completed_in_order) ++measurement.trials_completed;
        for (std::size_t f = 0; f < finders.size(); ++f) {
          replay(scene.characters.front(), seed, trial.trace, finders[f], settings.threshold_m, tallies[f]);
        }
      }
    }
    for (std::size_t f = 0; f < finders.size(); ++f) {
      const Tally& t = tallies[f];
      JumpRow row;
      row.method = finders[f].name;
      row.guidance = guidance;
      row.strokes = t.strokes;
      row.ws_ticks = t.ws_ticks;
      row.jumps = t.jumps;
      row.jumps_at_switch = t.jumps_at_switch;
      row.strokes_with_jump = t.strokes_with_jump;
      row.max_jump_m = t.max_jump_m;
      row.where = t.where;
      if (t.strokes > 0) {
        row.jumps_per_stroke = static_cast<double>(t.jumps) / static_cast<double>(t.strokes);
        row.frac_strokes_with_jump =
            static_cast<double>(t.strokes_with_jump) / static_cast<double>(t.strokes);
      }
      measurement.rows.push_back(row);
    }
  }
  return measurement;
}

std::string foot_jumps_json(const JumpMeasurement& measurement) {
  nlohmann::json rows = nlohmann::json::array();
  for (const JumpRow& row : measurement.rows) {
    rows.push_back({{"method", row.method},
                    {"guidance", row.guidance},
                    {"strokes", row.strokes},
                    {"ws_ticks", row.ws_ticks},
                    {"jumps", row.jumps},
                    {"jumps_at_element_switch", row.jumps_at_switch},
                    {"jumps_per_stroke", row.jumps_per_stroke},
                    {"frac_strokes_with_jump", row.frac_strokes_with_jump},
                    {"max_jump_m", row.max_jump_m}});
  }
  return rows.dump(2) + "\n";
}

std::string foot_jumps_markdown(const JumpMeasurement& measurement, const std::string& command) {
  const JumpSettings& s = measurement.settings;
  std::string seeds;
  for (const std::uint64_t seed : s.seeds) seeds += (seeds.empty() ? "" : ", ") + std::to_string(seed);
  const std::string threshold_mm = format_number("%g", s.threshold_m * 1e3);
  std::ostringstream out;
  out << kJumpsGeneratedBegin << "\n\nGenerated by `" << command << "`.\n\n";
  out << measurement.trials << " simulated trials: " << measurement.characters << " characters"
      << (s.characters.empty() ? " (every embedded one)" : " (" + encode_utf8(s.characters) + ")")
      << " x seeds " << seeds
      << " x guidance on and off; lock-step at 1 kHz on the simulated Phantom Desktop, novice "
      << "writer; " << measurement.trials_completed
      << " of them completed every stroke in order. The renderer "
      << "used `exact`. Each trace's WS ticks are replayed through each method on the element that was "
      << "active; a jump is a tick whose foot point moved more than " << threshold_mm
      << " mm from the previous WS tick of the same stroke. `exact` and `newton` (8 starts x 6 iterations) "
      << "run every tick, `tracker` is `NearestPointTracker` with its defaults (reset when the element "
      << "changes), `subdivision` is the paper's method with e = "
      << format_number("%g", s.subdivision_tolerance_m * 1e3)
      << " mm (the paper gives no value). A stroke counts once per trial, over all its attempts.\n\n";
  out << "| method | guidance | strokes | WS ticks | jumps > " << threshold_mm
      << " mm | of which at an element switch | jumps per stroke | strokes with a jump | largest move (mm) "
         "|\n";
  out << "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const JumpRow& row : measurement.rows) {
    out << "| " << row.method << " | " << (row.guidance ? "on" : "off") << " | " << row.strokes << " | "
        << row.ws_ticks << " | " << row.jumps << " | " << row.jumps_at_switch << " | "
        << format_number("%.3f", row.jumps_per_stroke) << " | "
        << format_number("%.2f %%", 100.0 * row.frac_strokes_with_jump) << " | "
        << format_number("%.2f", row.max_jump_m * 1e3) << " |\n";
  }
  constexpr std::size_t kListed = 12;
  out << "\nStrokes with a jump (character, stroke, seed; the first " << kListed << "):\n\n";
  for (const JumpRow& row : measurement.rows) {
    if (row.where.empty()) continue;
    out << "- " << row.method << ", guidance " << (row.guidance ? "on" : "off") << ": ";
    for (std::size_t i = 0; i < row.where.size() && i < kListed; ++i)
      out << (i == 0 ? "" : "; ") << row.where[i];
    if (row.where.size() > kListed) out << "; and " << row.where.size() - kListed << " more";
    out << "\n";
  }
  out << "\n" << kGeneratedEnd << "\n";
  return out.str();
}

}  // namespace calligraphy::cli
