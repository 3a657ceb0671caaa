#include "eval/corpus_fidelity.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/polyline.hpp"
#include "calligraphy/model/scene.hpp"
#include "eval/corpus_fit.hpp"
#include "eval/report_numbers.hpp"

namespace calligraphy::cli {
namespace {

void measure_stroke(const Stroke& fitted, const Stroke& stored, StrokeDeviation& d) {
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

FidelityRow measure_tolerance(const CharacterLibrary& library, double tolerance, int steps, unsigned threads,
                              bool log_progress) {
  FitOptions options;
  options.tolerance = tolerance;
  CorpusFit fit =
      fit_corpus(library, options, threads, "tolerance " + format_number("%g", tolerance), log_progress);
  const CorpusStoreOptions store_options{steps, tolerance};
  drop_unstorable(fit, store_options);  // counted with the characters not modelled
  const auto bytes = encode_corpus_store(fit.characters, store_options);
  const CorpusStore store = CorpusStore::from_bytes(bytes, "memory");
  FidelityRow row;
  row.tolerance = tolerance;
  row.characters = fit.characters.size();
  row.failures = fit.failures.size();
  row.bytes = bytes.size();
  row.fit_wall_s = fit.wall_s;
  row.fit_cpu_s = fit.fit_cpu_s;
  row.threads = fit.threads;
  std::size_t elements = 0;
  for (std::size_t ci = 0; ci < fit.characters.size(); ++ci) {
    const Character& c = fit.characters[ci];
    const Character stored = store.load(c.code_point);
    for (std::size_t s = 0; s < c.strokes.size(); ++s) {
      ++row.strokes;
      const double fitter = fit.fitter_deviation[ci][s];
      row.fitter_max = std::max(row.fitter_max, fitter);
      if (fitter > tolerance) ++row.fitter_beyond;
      elements += c.strokes[s].elements.size();
      StrokeDeviation before;
      measure_stroke(c.strokes[s], c.strokes[s], before);
      row.max_before = std::max(row.max_before, before.max_kept);
      StrokeDeviation after;
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
  row.elements_per_stroke =
      row.strokes ? static_cast<double>(elements) / static_cast<double>(row.strokes) : 0.0;
  return row;
}

double share_percent(std::size_t part, std::size_t whole) {
  return 100.0 * static_cast<double>(part) / static_cast<double>(std::max<std::size_t>(1, whole));
}

}  // namespace

std::vector<FidelityRow> measure_corpus_fidelity(const CharacterLibrary& library,
                                                 const std::vector<double>& tolerances, int steps_per_unit,
                                                 unsigned threads, bool log_progress) {
  if (tolerances.empty()) throw InvalidArgument("corpus fidelity: no tolerance given");
  std::vector<FidelityRow> rows;
  for (double tolerance : tolerances) {
    if (!(tolerance > 0.0))
      throw InvalidArgument("corpus fidelity: tolerance " + format_number("%g", tolerance) + " is not > 0");
    rows.push_back(measure_tolerance(library, tolerance, steps_per_unit, threads, log_progress));
  }
  return rows;
}

std::string corpus_fidelity_markdown(const std::vector<FidelityRow>& rows, int steps_per_unit) {
  const double mm_per_unit = 1000.0 * SceneLayout{}.character_size_m / kDataBoxSize;
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
    md << "| " << format_number("%g", r.tolerance) << " | " << format_number("%.2f", r.elements_per_stroke)
       << " | " << r.bytes << " | "
       << format_number("%.1f", static_cast<double>(r.bytes) /
                                    static_cast<double>(std::max<std::size_t>(1, r.characters)))
       << " | " << format_number("%.2f", r.after.max_kept) << " | "
       << format_number("%.3f", r.after.max_kept * mm_per_unit) << " | " << format_number("%.2f", mean)
       << " | " << format_number("%.3f", mean * mm_per_unit) << " | " << format_number("%.2f", r.max_before)
       << " | " << format_number("%.1f", r.after.max_all) << " | " << r.strokes_beyond << " ("
       << format_number("%.2f", share_percent(r.strokes_beyond, r.strokes)) << " %) | "
       << encode_utf8(r.worst_character) << " stroke " << r.worst_stroke << " | "
       << format_number("%.2f", r.fitter_max) << " | " << r.fitter_beyond << " ("
       << format_number("%.2f", share_percent(r.fitter_beyond, r.strokes)) << " %) | "
       << format_number("%.2f", r.fit_wall_s) << " (" << r.threads << ") | "
       << format_number("%.2f", r.fit_cpu_s) << " |\n";
  }
  if (!rows.empty()) {
    md << "\n"
       << rows.front().characters << " characters (" << rows.front().failures
       << " not modelled), quantisation 1/" << steps_per_unit << " data unit; mm at the default layout ("
       << format_number("%.0f", 1000.0 * SceneLayout{}.character_size_m) << " mm per 1024 units).\n";
  }
  return md.str();
}

}  // namespace calligraphy::cli
