#pragma once
// Fits a whole folder of hanzi-writer-data characters on a pool of threads, with a progress bar on
// stderr and timings split into read+parse and fit (shared by `corpus build` and `corpus fidelity`).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"

namespace calligraphy::cli {

struct CorpusFitFailure {
  char32_t code_point = 0;
  std::string reason;
};

struct CorpusFit {
  std::vector<Character> characters;  ///< sorted by code point; medians kept in each stroke
  /// Per character, per stroke: `FittedStroke::max_deviation`, the fitter's own measure (from the median
  /// after brush hooks are trimmed and rounded corners snapped to their lines' intersection).
  std::vector<std::vector<double>> fitter_deviation;
  std::vector<CorpusFitFailure> failures;
  unsigned threads = 0;
  double wall_s = 0.0;            ///< reading, parsing and fitting, wall clock
  double read_parse_cpu_s = 0.0;  ///< summed over threads
  double fit_cpu_s = 0.0;         ///< summed over threads
};

/// The folder scripts/fetch-hanzi-writer-data.sh fills ($XDG_CACHE_HOME when absolute, else ~/.cache, then
/// calligraphy/hanzi-writer-data-2.0.1), whether or not it has been filled.
std::filesystem::path fetched_corpus_folder();
/// `fetched_corpus_folder()` when the fetch completed (its `.complete` marker exists), else nullopt.
std::optional<std::filesystem::path> complete_fetched_corpus_folder();
/// std::thread::hardware_concurrency(), at least 1.
unsigned default_corpus_threads();
/// Fits every character of the folder. `label` prefixes the progress bar, drawn on stderr when it is a
/// terminal; elsewhere one line per 10 % with `log_progress`, else none.
CorpusFit fit_corpus(const CharacterLibrary& library, const FitOptions& options, unsigned threads,
                     const std::string& label, bool log_progress);
/// Moves each fitted character that a store of `options` cannot hold (`encode_corpus_store` refuses it
/// alone: a stroke fitted with more than 270 elements, a coordinate beyond the store's range) from
/// `fit.characters` to `fit.failures` with the store's reason, so that the store holds the others and the
/// character is listed as the others that could not be modelled are. Failures stay in code point order.
void drop_unstorable(CorpusFit& fit, const CorpusStoreOptions& options);

}  // namespace calligraphy::cli
