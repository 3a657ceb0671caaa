// `calligraphy corpus build|stats|fidelity`: the whole hanzi-writer-data corpus modelled into a compact
// store (docs/corpus.md), its statistics, and the fidelity/size trade over fitting tolerances.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "cli/commands.hpp"
#include "core/unicode.hpp"
#include "eval/corpus_fit.hpp"
#include "model/polyline.hpp"

namespace calligraphy::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

int steps_from(const Arguments& arguments) {
  const double steps = arguments.number_or("steps", CorpusStoreOptions{}.steps_per_unit);
  if (steps != 1 && steps != 2 && steps != 4 && steps != 8 && steps != 16) {
    throw UsageError("--steps expects 1, 2, 4, 8 or 16 (quantisation steps per data unit)");
  }
  return static_cast<int>(steps);
}

FitOptions fit_options_from(const Arguments& arguments) {
  FitOptions options;
  options.tolerance = arguments.number_or("tolerance", options.tolerance);
  if (!(options.tolerance > 0.0)) throw UsageError("--tolerance expects a positive number of data units");
  return options;
}

void print_failures(const CorpusFit& fit) {
  std::printf("  not modelled        %zu\n", fit.failures.size());
  for (const auto& f : fit.failures) {
    std::printf("    %s: %s\n", describe_character(f.code_point).c_str(), f.reason.c_str());
  }
}

int corpus_build(const Args& args) {
  const Arguments arguments(args, {"data", "out", "tolerance", "steps", "threads"}, {});
  if (arguments.positionals().size() != 1) throw UsageError("corpus build takes no positional argument");
  const auto out = arguments.option("out");
  if (!out) throw UsageError("corpus build needs --out FILE");
  const CharacterLibrary library = CharacterLibrary::from_directory(corpus_folder(arguments));
  const FitOptions fit_options = fit_options_from(arguments);
  CorpusStoreOptions store_options;
  store_options.steps_per_unit = steps_from(arguments);
  store_options.fit_tolerance = fit_options.tolerance;

  const auto start = Clock::now();
  const CorpusFit fit = fit_corpus(library, fit_options, corpus_threads(arguments), "fitting");
  const auto write_start = Clock::now();
  write_corpus_store(*out, fit.characters, store_options);
  const double write_s = std::chrono::duration<double>(Clock::now() - write_start).count();
  const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
  const auto bytes = std::filesystem::file_size(*out);

  std::printf("corpus store %s from %s\n", out->c_str(), library.description().c_str());
  std::printf("  characters          %zu\n", fit.characters.size());
  print_failures(fit);
  std::printf("  tolerance           %.3g data units, quantisation 1/%d unit\n", fit_options.tolerance,
              store_options.steps_per_unit);
  std::printf(
      "  store               %ju bytes, %.1f bytes per character\n", static_cast<std::uintmax_t>(bytes),
      fit.characters.empty() ? 0.0 : static_cast<double>(bytes) / static_cast<double>(fit.characters.size()));
  std::printf(
      "  time                %.2f s total: read+fit %.2f s wall on %u threads (summed over threads: "
      "read+parse %.2f s, "
      "fit %.2f s), encode+write %.3f s\n",
      total_s, fit.wall_s, fit.threads, fit.read_parse_cpu_s, fit.fit_cpu_s, write_s);
  return fit.failures.empty() ? 0 : 1;
}

int corpus_stats(const Args& args) {
  const Arguments arguments(args, {}, {"json"});
  if (arguments.positionals().size() != 2) throw UsageError("corpus stats takes one FILE");
  const CorpusStore store = CorpusStore::open(arguments.positionals()[1]);
  const CorpusStoreInfo& info = store.info();
  const CorpusStoreStats stats = corpus_store_stats(store);
  const double per_char =
      info.character_count ? static_cast<double>(info.file_bytes) / static_cast<double>(info.character_count)
                           : 0.0;
  const std::string checksums = stats.errors.empty() ? "ok (header, index and every record)"
                                                     : std::to_string(stats.errors.size()) + " bad records";
  if (arguments.flag("json")) {
    nlohmann::json histogram = nlohmann::json::array();
    for (const auto& [id, count] : stats.strokes_by_typical_id) {
      histogram.push_back(
          {{"id", id}, {"acronym", std::string(typical_stroke(id).acronym)}, {"strokes", count}});
    }
    const nlohmann::json doc = {
        {"file", store.name()},
        {"format_version", std::to_string(info.version_major) + "." + std::to_string(info.version_minor)},
        {"characters", info.character_count},
        {"strokes", stats.strokes},
        {"elements", stats.elements},
        {"bytes", info.file_bytes},
        {"bytes_per_character", per_char},
        {"fit_tolerance", info.fit_tolerance},
        {"steps_per_unit", info.steps_per_unit},
        {"checksums_ok", stats.errors.empty()},
        {"errors", stats.errors},
        {"typical_stroke_histogram", histogram}};
    std::cout << doc.dump(2) << "\n";
  } else {
    std::printf("corpus store %s\n", store.name().c_str());
    std::printf("  format version      %d.%d\n", info.version_major, info.version_minor);
    std::printf("  characters          %zu\n", info.character_count);
    std::printf("  strokes             %zu\n", stats.strokes);
    std::printf(
        "  elements            %zu (%.2f per stroke)\n", stats.elements,
        stats.strokes ? static_cast<double>(stats.elements) / static_cast<double>(stats.strokes) : 0.0);
    std::printf("  bytes               %zu (header %zu, index %zu, records %zu); %.1f per character\n",
                info.file_bytes, info.header_bytes, info.index_bytes, info.record_bytes, per_char);
    std::printf("  fit tolerance       %.3g data units; quantisation 1/%d unit (max error %.3f units)\n",
                info.fit_tolerance, info.steps_per_unit, info.max_quantisation_error());
    std::printf("  checksums           %s\n", checksums.c_str());
    for (const auto& e : stats.errors) std::printf("    %s\n", e.c_str());
    std::printf("  typical strokes:\n");
    for (const auto& [id, count] : stats.strokes_by_typical_id) {
      std::printf(
          "    %2d %-6s %-8s %7zu  %5.2f %%\n", id, std::string(typical_stroke(id).acronym).c_str(),
          std::string(typical_stroke(id).name_zh).c_str(), count,
          100.0 * static_cast<double>(count) / static_cast<double>(std::max<std::size_t>(1, stats.strokes)));
    }
  }
  return stats.errors.empty() ? 0 : 1;
}

// Deviation of a stored (quantised) stroke from its median: distances of the median, resampled every
// 4 data units, to the elements (each sampled at 64 steps). "Kept" leaves out the brush entry/exit
// hooks the fitter trims on purpose (detected as a fitted end that is not the median's end).
struct Deviation {
  double max_kept = 0.0;
  double sum_kept = 0.0;
  std::size_t samples_kept = 0;
  double max_all = 0.0;
};

void measure_stroke(const Stroke& fitted, const Stroke& stored, Deviation& d) {
  std::vector<Vec2> curve;
  for (const auto& e : stored.elements) {
    const auto s = sample_element(e, 64);
    curve.insert(curve.end(), s.begin(), s.end());
  }
  std::vector<Vec2> median = without_repeats(fitted.median);
  for (const Vec2& p : median) d.max_all = std::max(d.max_all, distance_to_polyline(p, curve));
  if (median.size() >= 3 && fitted.elements.front().start() != median.front()) median.erase(median.begin());
  if (median.size() >= 3 && fitted.elements.back().end() != median.back()) median.pop_back();
  const auto samples = median.size() >= 2 ? resample(median, 4.0) : median;
  for (const Vec2& p : samples) {
    const double dist = distance_to_polyline(p, curve);
    d.max_kept = std::max(d.max_kept, dist);
    d.sum_kept += dist;
    ++d.samples_kept;
  }
}

struct FidelityRow {
  double tolerance = 0.0;
  std::size_t characters = 0;
  std::size_t failures = 0;
  double elements_per_stroke = 0.0;
  std::size_t bytes = 0;
  double max_before = 0.0;  // unquantised
  double fitter_max = 0.0;  // FittedStroke::max_deviation
  std::size_t fitter_beyond = 0;
  Deviation after;  // quantised, as loaded from the store
  std::size_t strokes = 0;
  std::size_t strokes_beyond = 0;  // max deviation above tolerance + quantisation error
  char32_t worst_character = 0;
  std::size_t worst_stroke = 0;
  double fit_wall_s = 0.0;
  double fit_cpu_s = 0.0;
  unsigned threads = 0;
};

std::vector<double> tolerances_from(const Arguments& arguments) {
  std::vector<double> out;
  std::stringstream list(arguments.option_or("tolerances", "2,5,10,20"));
  for (std::string item; std::getline(list, item, ',');) {
    try {
      out.push_back(std::stod(item));
    } catch (const std::exception&) {
      throw UsageError("--tolerances expects numbers separated by commas, got '" + item + "'");
    }
    if (!(out.back() > 0.0)) throw UsageError("--tolerances must be positive");
  }
  if (out.empty()) throw UsageError("--tolerances is empty");
  return out;
}

int corpus_fidelity(const Args& args) {
  const Arguments arguments(args, {"data", "tolerances", "markdown", "steps", "threads"}, {});
  const CharacterLibrary library = CharacterLibrary::from_directory(corpus_folder(arguments));
  const int steps = steps_from(arguments);
  const double mm_per_unit = 1000.0 * SceneLayout{}.character_size_m / kDataBoxSize;
  std::vector<FidelityRow> rows;
  for (double tolerance : tolerances_from(arguments)) {
    FitOptions options;
    options.tolerance = tolerance;
    const CorpusFit fit =
        fit_corpus(library, options, corpus_threads(arguments), "tolerance " + format("%g", tolerance));
    const auto bytes = encode_corpus_store(fit.characters, {steps, tolerance});
    const CorpusStore store = CorpusStore::from_bytes(bytes, "memory");
    FidelityRow row;
    row.tolerance = tolerance;
    row.characters = fit.characters.size();
    row.failures = fit.failures.size();
    row.bytes = bytes.size();
    row.fit_wall_s = fit.wall_s;
    row.fit_cpu_s = fit.fit_cpu_s;
    row.threads = fit.threads;
    std::size_t strokes = 0;
    std::size_t elements = 0;
    for (std::size_t ci = 0; ci < fit.characters.size(); ++ci) {
      const Character& c = fit.characters[ci];
      const Character stored = store.load(c.code_point);
      for (std::size_t s = 0; s < c.strokes.size(); ++s) {
        ++strokes;
        const double fitter = fit.fitter_deviation[ci][s];
        row.fitter_max = std::max(row.fitter_max, fitter);
        if (fitter > tolerance) ++row.fitter_beyond;
        elements += c.strokes[s].elements.size();
        Deviation before;
        measure_stroke(c.strokes[s], c.strokes[s], before);
        row.max_before = std::max(row.max_before, before.max_kept);
        Deviation after;
        measure_stroke(c.strokes[s], stored.strokes[s], after);
        if (after.max_kept > tolerance + store.info().max_quantisation_error()) ++row.strokes_beyond;
        if (after.max_kept > row.after.max_kept) {
          row.worst_character = c.code_point;
          row.worst_stroke = s + 1;
        }
        row.after.max_kept = std::max(row.after.max_kept, after.max_kept);
        row.after.max_all = std::max(row.after.max_all, after.max_all);
        row.after.sum_kept += after.sum_kept;
        row.after.samples_kept += after.samples_kept;
      }
    }
    row.strokes = strokes;
    row.elements_per_stroke = strokes ? static_cast<double>(elements) / static_cast<double>(strokes) : 0.0;
    rows.push_back(row);
  }

  std::ostringstream md;
  md << "| tolerance (units) | elements/stroke | store bytes | bytes/char | max dev (units) | max dev (mm) | "
        "mean dev (units) | mean dev (mm) | max dev before quantisation (units) | max dev incl. hooks "
        "(units) | "
        "strokes beyond tolerance | worst stroke | fitter's max dev (units) | strokes beyond, fitter's "
        "measure | fit time (s wall, threads) | fit thread-s |\n";
  md << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    const double mean =
        r.after.samples_kept ? r.after.sum_kept / static_cast<double>(r.after.samples_kept) : 0.0;
    md << "| " << format("%g", r.tolerance) << " | " << format("%.2f", r.elements_per_stroke) << " | "
       << r.bytes << " | "
       << format("%.1f",
                 static_cast<double>(r.bytes) / static_cast<double>(std::max<std::size_t>(1, r.characters)))
       << " | " << format("%.2f", r.after.max_kept) << " | " << format("%.3f", r.after.max_kept * mm_per_unit)
       << " | " << format("%.2f", mean) << " | " << format("%.3f", mean * mm_per_unit) << " | "
       << format("%.2f", r.max_before) << " | " << format("%.1f", r.after.max_all) << " | "
       << r.strokes_beyond << " ("
       << format("%.2f", 100.0 * static_cast<double>(r.strokes_beyond) /
                             static_cast<double>(std::max<std::size_t>(1, r.strokes)))
       << " %) | " << encode_utf8(r.worst_character) << " stroke " << r.worst_stroke << " | "
       << format("%.2f", r.fitter_max) << " | " << r.fitter_beyond << " ("
       << format("%.2f", 100.0 * static_cast<double>(r.fitter_beyond) /
                             static_cast<double>(std::max<std::size_t>(1, r.strokes)))
       << " %) | " << format("%.2f", r.fit_wall_s) << " (" << r.threads << ") | "
       << format("%.2f", r.fit_cpu_s) << " |\n";
  }
  md << "\n"
     << rows.front().characters << " characters (" << rows.front().failures
     << " not modelled), quantisation 1/" << steps << " data unit; mm at the default layout ("
     << format("%.0f", 1000.0 * SceneLayout{}.character_size_m) << " mm per 1024 units).\n";
  std::cout << md.str();
  if (const auto path = arguments.option("markdown")) {
    std::ofstream out(*path);
    out << md.str();
    if (!out) throw DataError(*path + ": cannot write");
  }
  return 0;
}

}  // namespace

int command_corpus(const Args& args) {
  const std::string sub = args.empty() ? "" : args[0];
  if (sub == "build") return corpus_build(args);
  if (sub == "stats") return corpus_stats(args);
  if (sub == "fidelity") return corpus_fidelity(args);
  throw UsageError("corpus expects build, stats or fidelity");
}

}  // namespace calligraphy::cli
