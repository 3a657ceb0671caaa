#pragma once
// Reports of the corpus commands (docs/corpus.md): what `calligraphy corpus build` prints after writing a
// store, and `calligraphy corpus stats` as JSON or for people.
#include <cstddef>
#include <string>

#include "calligraphy/model/corpus_store.hpp"
#include "eval/corpus_fit.hpp"

namespace calligraphy::cli {

/// Timings of `corpus build` [s].
struct CorpusBuildTimes {
  double total_s = 0.0;
  double encode_write_s = 0.0;
};

/// The summary of a build: characters, failures, tolerance, store size, timings.
std::string corpus_build_text(const std::string& store_name, const std::string& library_description,
                              const CorpusFit& fit, const CorpusStoreOptions& options, std::size_t bytes,
                              const CorpusBuildTimes& times);

/// The statistics of a store as a JSON object (keys file, format_version, characters, strokes, elements,
/// bytes, bytes_per_character, fit_tolerance, steps_per_unit, checksums_ok, errors,
/// typical_stroke_histogram), newline-terminated.
std::string corpus_stats_json(const CorpusStore& store, const CorpusStoreStats& stats);
/// The same for people, with the number of bad records (their errors are the caller's to print).
std::string corpus_stats_text(const CorpusStore& store, const CorpusStoreStats& stats);

}  // namespace calligraphy::cli
