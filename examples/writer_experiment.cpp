// An experiment scripted on simulated writers before recruiting people: the same seeded writers write
// each character with guidance on and off, and the pen traces are scored (docs/writer.md, "Measured").
//
//   example_writer_experiment                      a quick run on two embedded characters (exit 0 when
//                                                  every guided trial wrote every stroke in order)
//   example_writer_experiment --data DIR [--every 90] [--count 100] [--seeds 3] [--csv FILE]
//
// With --data (a hanzi-writer-data folder, e.g. what scripts/fetch-hanzi-writer-data.sh prints) the
// characters are every N-th code point of the CJK Unified Ideographs block (U+4E00-U+9FFF) in the
// folder, leaving out the embedded set, up to --count. Novice and foreign profiles, seeds 1..S.
#include <algorithm>
#include <calligraphy/analysis/score.hpp>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/sim/simulated_hand.hpp>
#include <calligraphy/trial/trial.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace {

using namespace calligraphy;

struct Run {
  char32_t character = 0;
  std::string profile;
  bool guidance = false;
  std::uint64_t seed = 0;
  double deviation_mm = 0.0;  // pooled over the matched strokes of the trace
  double renderer_deviation_mm =
      0.0;              // the trial recorder's: WS ticks of each accepted stroke's last attempt
  double time_s = 0.0;  // first to last pen-down sample
  std::size_t order_errors = 0;
  std::size_t backwards = 0;
  bool in_order = false;  // the renderer accepted every stroke, each in its turn
  std::size_t refusals = 0;
  std::size_t not_accepted = 0;  // strokes the writer wrote whole, saw not taken and wrote again
};

// One lock-step trial on the simulated device (run_simulated_trial), with the writer's log.
Run run_trial(const Scene& scene, const WriterProfile& profile, bool guidance, std::uint64_t seed) {
  TrialOptions options;
  options.force.guidance = guidance;
  options.max_duration_s = 300.0;
  SimulationOptions simulation;
  simulation.writer = profile;
  simulation.seed = seed;
  std::optional<WriterLog> log;
  const TrialResult result = run_simulated_trial(scene, options, simulation, &log);

  std::vector<PenSample> pen;
  for (const TrialSample& s : result.trace) {
    pen.push_back(PenSample{s.time_s, s.position_m.head<2>(), s.position_m.z() <= scene.layout.paper_z_m});
  }
  const CharacterScore score = score_trace(scene.characters[0], pen);
  Run run;
  run.character = scene.characters[0].code_point;
  run.profile = profile.name;
  run.guidance = guidance;
  run.seed = seed;
  run.deviation_mm = score.totals.deviation ? score.totals.deviation->mean_m * 1e3 : std::nan("");
  run.renderer_deviation_mm = result.metrics.mean_deviation_m.value_or(std::nan("")) * 1e3;
  run.time_s = score.totals.total_time_s.value_or(std::nan(""));  // NaN: the pen never touched
  run.order_errors = score.order_errors;
  run.backwards = score.backwards_strokes;
  run.in_order = result.metrics.completed_in_order;
  run.refusals = log ? log->refusals : 0;
  run.not_accepted = log ? log->not_accepted : 0;
  return run;
}

std::string utf8(char32_t c) {
  std::string s;
  if (c < 0x80) {
    s += static_cast<char>(c);
  } else if (c < 0x800) {
    s += static_cast<char>(0xC0 | (c >> 6));
    s += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    s += static_cast<char>(0xE0 | (c >> 12));
    s += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    s += static_cast<char>(0xF0 | (c >> 18));
    s += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    s += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (c & 0x3F));
  }
  return s;
}

// Median and quartiles (linear interpolation between order statistics).
struct Spread {
  double q1 = 0.0;
  double median = 0.0;
  double q3 = 0.0;
};
Spread spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const auto at = [&](double p) {
    const double x = p * static_cast<double>(v.size() - 1);
    const auto i = static_cast<std::size_t>(x);
    return i + 1 < v.size() ? v[i] + (x - static_cast<double>(i)) * (v[i + 1] - v[i]) : v[i];
  };
  return v.empty() ? Spread{} : Spread{at(0.25), at(0.5), at(0.75)};
}

const Run* find(const std::vector<Run>& runs, char32_t c, const std::string& profile, bool guidance,
                std::uint64_t seed) {
  for (const Run& r : runs) {
    if (r.character == c && r.profile == profile && r.guidance == guidance && r.seed == seed) return &r;
  }
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data;
  std::string csv;
  std::size_t every = 90;
  std::size_t count = 100;
  std::uint64_t seeds = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const std::string value = argv[i + 1];
    if (key == "--data")
      data = value;
    else if (key == "--csv")
      csv = value;
    else if (key == "--every")
      every = std::stoul(value);
    else if (key == "--count")
      count = std::stoul(value);
    else if (key == "--seeds")
      seeds = std::stoull(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  try {
    const CharacterLibrary embedded = CharacterLibrary::embedded();
    std::vector<char32_t> characters;
    CharacterLibrary library = embedded;
    if (data.empty()) {
      characters = {U'十', U'口'};
    } else {
      library = CharacterLibrary::from_directory(data);
      std::vector<char32_t> block;
      for (const char32_t c : library.characters()) {
        if (c >= 0x4E00 && c <= 0x9FFF) block.push_back(c);
      }
      for (std::size_t i = 0; i < block.size() && characters.size() < count; i += every) {
        if (!embedded.contains(block[i])) characters.push_back(block[i]);
      }
    }
    std::vector<Run> runs;
    for (const char32_t c : characters) {
      Scene scene;
      try {
        scene = Scene::lay_out({library.load(c)});
      } catch (const std::exception& e) {
        std::fprintf(stderr, "skipped %s: %s\n", utf8(c).c_str(), e.what());
        continue;
      }
      for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
        for (const char* profile : {"novice", "foreign"}) {
          for (const bool guidance : {false, true})
            runs.push_back(run_trial(scene, writer_profile(profile), guidance, seed));
        }
      }
    }
    if (!csv.empty()) {
      std::ofstream out(csv);
      out << "character,code_point,profile,guidance,seed,mean_deviation_mm,renderer_deviation_mm,writing_"
             "time_s,"
             "order_errors,backwards_strokes,completed_in_order,refusals,not_accepted\n";
      for (const Run& r : runs) {
        char line[256];
        std::snprintf(line, sizeof line, "%s,U+%04X,%s,%d,%llu,%.4f,%.4f,%.3f,%zu,%zu,%d,%zu,%zu\n",
                      utf8(r.character).c_str(), static_cast<unsigned>(r.character), r.profile.c_str(),
                      r.guidance ? 1 : 0, static_cast<unsigned long long>(r.seed), r.deviation_mm,
                      r.renderer_deviation_mm, r.time_s, r.order_errors, r.backwards, r.in_order ? 1 : 0,
                      r.refusals, r.not_accepted);
        out << line;
      }
    }

    // Paired comparisons, novice: guidance on against off for the same character and seed.
    std::vector<double> dev_off, dev_on, rdev_off, rdev_on, time_off, time_on, time_ratio;
    std::size_t pairs = 0, dev_lower = 0, rdev_lower = 0, time_lower = 0;
    for (const Run& r : runs) {
      if (r.profile != "novice" || r.guidance) continue;
      const Run* on = find(runs, r.character, "novice", true, r.seed);
      if (on == nullptr) continue;
      ++pairs;
      dev_off.push_back(r.deviation_mm);
      dev_on.push_back(on->deviation_mm);
      rdev_off.push_back(r.renderer_deviation_mm);
      rdev_on.push_back(on->renderer_deviation_mm);
      if (on->renderer_deviation_mm < r.renderer_deviation_mm) ++rdev_lower;
      time_off.push_back(r.time_s);
      time_on.push_back(on->time_s);
      time_ratio.push_back(on->time_s / r.time_s);
      if (on->deviation_mm < r.deviation_mm) ++dev_lower;
      if (on->time_s < r.time_s) ++time_lower;
    }
    std::size_t foreign_off = 0, off_order = 0, off_backwards = 0, foreign_on = 0, on_in_order = 0,
                on_order = 0, on_backwards = 0, guided = 0, guided_in_order = 0;
    for (const Run& r : runs) {
      if (r.guidance) {
        ++guided;
        if (r.in_order) ++guided_in_order;
      }
      if (r.profile != "foreign") continue;
      if (!r.guidance) {
        ++foreign_off;
        if (r.order_errors > 0) ++off_order;
        if (r.backwards > 0) ++off_backwards;
      } else {
        ++foreign_on;
        if (r.in_order) ++on_in_order;
        if (r.order_errors > 0) ++on_order;
        if (r.backwards > 0) ++on_backwards;
      }
    }
    const auto show = [](const char* what, const Spread& s) {
      std::printf("  %-28s median %.3f  IQR %.3f-%.3f\n", what, s.median, s.q1, s.q3);
    };
    std::printf("characters %zu, seeds %llu, trials %zu\n", runs.size() / (4 * seeds),
                static_cast<unsigned long long>(seeds), runs.size());
    std::printf("novice, %zu pairs (same character and seed):\n", pairs);
    std::printf(
        "  guidance lowers the trace-scored mean deviation in %zu of %zu (%.1f %%)\n", dev_lower, pairs,
        100.0 * static_cast<double>(dev_lower) / static_cast<double>(std::max<std::size_t>(pairs, 1)));
    std::printf(
        "  guidance lowers the recorder's mean deviation in %zu of %zu (%.1f %%)\n", rdev_lower, pairs,
        100.0 * static_cast<double>(rdev_lower) / static_cast<double>(std::max<std::size_t>(pairs, 1)));
    std::printf(
        "  guidance lowers the writing time in %zu of %zu (%.1f %%)\n", time_lower, pairs,
        100.0 * static_cast<double>(time_lower) / static_cast<double>(std::max<std::size_t>(pairs, 1)));
    show("mean deviation off [mm]", spread(dev_off));
    show("mean deviation on [mm]", spread(dev_on));
    show("recorder's deviation off [mm]", spread(rdev_off));
    show("recorder's deviation on [mm]", spread(rdev_on));
    show("writing time off [s]", spread(time_off));
    show("writing time on [s]", spread(time_on));
    show("time on / time off", spread(time_ratio));
    std::printf("foreign, without guidance: order errors in %zu of %zu trials, backwards strokes in %zu\n",
                off_order, foreign_off, off_backwards);
    std::printf(
        "foreign, with guidance: every stroke in order in %zu of %zu; traces with order errors %zu, "
        "with backwards strokes %zu\n",
        on_in_order, foreign_on, on_order, on_backwards);
    for (const char* profile : {"novice", "foreign"}) {
      for (const bool guidance : {false, true}) {
        std::size_t trials = 0, in_order = 0, rewritten = 0;
        for (const Run& r : runs) {
          if (r.profile != profile || r.guidance != guidance) continue;
          ++trials;
          if (r.in_order) ++in_order;
          rewritten += r.not_accepted;
        }
        std::printf(
            "%s, guidance %s: every stroke in order in %zu of %zu; strokes written again after the "
            "display did not take them %zu\n",
            profile, guidance ? "on" : "off", in_order, trials, rewritten);
      }
    }
    std::printf("all guided trials: every stroke in order in %zu of %zu\n", guided_in_order, guided);
    return guided_in_order == guided ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
