#pragma once
// The fidelity/size trade of the corpus store over fitting tolerances (`calligraphy corpus fidelity`,
// docs/corpus.md): for each tolerance, the whole corpus is fitted, encoded into a store in memory and
// loaded back, and every stored (quantised) stroke is compared with its median.
#include <cstddef>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::cli {

/// Deviation of stored strokes from their medians [data units]: distances of the median, resampled every
/// 4 data units, to the elements (each sampled at 64 steps). "Kept" leaves out the brush entry/exit hooks
/// the fitter trims on purpose (detected as a fitted end that is not the median's end).
struct StrokeDeviation {
  double max_kept = 0.0;
  double sum_kept = 0.0;
  std::size_t samples_kept = 0;
  double max_all = 0.0;
};

/// One tolerance.
struct FidelityRow {
  double tolerance = 0.0;  ///< [data units]
  std::size_t characters = 0;
  std::size_t failures = 0;
  double elements_per_stroke = 0.0;
  std::size_t bytes = 0;
  double max_before = 0.0;  ///< unquantised
  double fitter_max = 0.0;  ///< FittedStroke::max_deviation
  std::size_t fitter_beyond = 0;
  StrokeDeviation after;  ///< quantised, as loaded from the store
  std::size_t strokes = 0;
  std::size_t strokes_beyond = 0;  ///< max deviation above tolerance + quantisation error
  char32_t worst_character = 0;
  std::size_t worst_stroke = 0;  ///< 1-based
  double fit_wall_s = 0.0;
  double fit_cpu_s = 0.0;
  unsigned threads = 0;
};

/// Fits, stores and measures the corpus at each tolerance (> 0) with `steps_per_unit` quantisation.
/// Throws InvalidArgument for no or non-positive tolerances, and what fitting and encoding throw.
/// `log_progress`: as fit_corpus's.
std::vector<FidelityRow> measure_corpus_fidelity(const CharacterLibrary& library,
                                                 const std::vector<double>& tolerances, int steps_per_unit,
                                                 unsigned threads, bool log_progress);

/// The Markdown table of the rows, with a closing line on the corpus and the units.
std::string corpus_fidelity_markdown(const std::vector<FidelityRow>& rows, int steps_per_unit);

}  // namespace calligraphy::cli
