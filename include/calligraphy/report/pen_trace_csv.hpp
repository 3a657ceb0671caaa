#pragma once
/// \file pen_trace_csv.hpp
/// Reading a pen trace from CSV: the one parser of trace files, for `score_trace` (analysis/score.hpp) and
/// for a saved trial's trace (`trial_csv`, trial_report.hpp) that the per-trial pages draw
/// (study/session_reader.hpp).
///
/// Format: comma-separated, one header line naming the columns, then one sample a line. Columns are found
/// by header name (others are ignored, order is free): `t` time [s], `x` and `y` the pen tip, and either
/// `pen` (1 = touching the paper, 0 = lifted) or `z`, the height of the tip [m] (the pen touches when
/// z - the paper's height <= the contact threshold); with `PenTraceCsvOptions::read_force`, also `fx` and
/// `fy`, the force [N]. Blank lines and lines starting with `#` are skipped; a line
/// may end in CR LF; fields may be padded with spaces; no quoting. Times must not decrease. A UTF-8
/// byte-order mark at the start (as spreadsheet programs write) is skipped.
///
/// Limits, refused while reading (before the rest of the file is parsed): at most
/// `PenTraceCsvOptions::max_file_bytes` bytes, `max_samples` samples and `max_pen_down_segments` pen-down
/// segments (maximal runs of samples with the pen down), the segments `score_trace` takes
/// (ScoreOptions::max_segments).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// Units of the x and y columns.
enum class TraceUnits {
  metres,  ///< the paper plane of the character's placement [m], as a Scene places it
  data,    ///< the character's 1024-unit data box, y up; converted with its Placement
};

/// Parses "metres" or "data". Throws InvalidArgument naming the value otherwise.
TraceUnits parse_trace_units(std::string_view name);

/// Options of the reader.
struct PenTraceCsvOptions {
  TraceUnits units = TraceUnits::metres;
  /// With a `z` column: the pen touches the paper when z <= this [m] (kPenContactThresholdM, score.hpp).
  /// Finite.
  double contact_threshold_m = kPenContactThresholdM;
  /// With a `z` column: the height of the paper [m], which z is measured from (a trial's trace gives z in
  /// device space: its scene's SceneLayout::paper_z_m). Finite.
  double paper_z_m = 0.0;
  /// Also read the columns `fx` and `fy` [N] (then required), as a trial's trace has them.
  bool read_force = false;
  /// Larger files are refused (256 MiB), and a gzip file whose text is larger.
  std::uintmax_t max_file_bytes = std::uintmax_t{256} << 20;
  /// A trace with more pen-down segments is refused at the line that starts the first one too many
  /// (ScoreOptions::max_segments, what one scored trace may have). > 0.
  std::size_t max_pen_down_segments = kMaxScoredSegments;
  /// A trace with more samples is refused at the line of the first one too many: 1,000,000 is over 16
  /// minutes at 1 kHz, and scoring takes time in proportion to the samples (a few seconds at the limit). > 0.
  std::size_t max_samples = 1'000'000;
  /// When set, called now and then while parsing with the bytes parsed so far and the text's size (for
  /// a progress display); it may throw to stop the reading.
  std::function<void(std::size_t parsed_bytes, std::size_t total_bytes)> progress;
};

/// Parses CSV text. `source` names the text in errors; `placement` converts data units to metres. Throws
/// DataError naming source:line, the column (number and name) and the value for a missing or duplicate
/// column, a row with the wrong number of fields, a value that is not a finite number (or not 0/1 for
/// `pen`), a time below the previous one, or more samples or pen-down segments than options.max_samples or
/// max_pen_down_segments;
/// InvalidArgument for bad options.
std::vector<PenSample> parse_pen_trace_csv(std::string_view text, const std::string& source,
                                           const Placement& placement,
                                           const PenTraceCsvOptions& options = {});

/// One sample of a trace as `for_each_pen_trace_row` gives it.
struct PenTraceRow {
  PenSample sample;
  /// |(fx, fy)|, the force in the paper plane [N], with PenTraceCsvOptions::read_force; 0 without.
  double in_plane_force_n = 0.0;
};

/// Reads a CSV file as `read_pen_trace_csv` does (the same format, limits and errors), calling `row` with
/// each sample in turn instead of keeping them: memory holds a block of the file, not its samples. `row` may
/// throw to stop the reading. A trace saved as HDF5 (a session's `STEM.trace.h5`, trace_hdf5.hpp, by its
/// first bytes) is read whole, its columns `t`, `x`, `y`, `z` (and `fx`, `fy`), with the same limits and
/// checks; its errors name the sample (1-based) instead of the line.
void for_each_pen_trace_row(const std::filesystem::path& file, const Placement& placement,
                            const PenTraceCsvOptions& options, const std::function<void(const PenTraceRow&)>& row);

/// As `for_each_pen_trace_row`, from the bytes of a trace file already read whole (an HDF5 trace, gzip or
/// plain CSV, by their first bytes), with the same limits, checks and errors; `source` names the file in
/// them. For a reader that also hashes the bytes (a saved trial's trace against its record's SHA-256): the
/// file is read once. Memory holds the bytes and, for gzip, the text.
void for_each_pen_trace_row_of_bytes(std::string_view bytes, const std::string& source,
                                     const Placement& placement, const PenTraceCsvOptions& options,
                                     const std::function<void(const PenTraceRow&)>& row);

/// Reads and parses a CSV file, a block at a time (memory holds the samples, not the file). A gzip file
/// (RFC 1952, by its first bytes: an older saved trial's `.csv.gz`) is decompressed on the way; an HDF5
/// trace is read as `for_each_pen_trace_row` reads it. Throws DataError
/// naming the file when it does not exist, is not a regular file, is larger than options.max_file_bytes
/// (on disk or decompressed), is damaged or truncated gzip or
/// cannot be read, and as `parse_pen_trace_csv`.
std::vector<PenSample> read_pen_trace_csv(const std::filesystem::path& file, const Placement& placement,
                                          const PenTraceCsvOptions& options = {});

}  // namespace calligraphy
