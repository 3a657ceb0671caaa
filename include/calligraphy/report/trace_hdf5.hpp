#pragma once
/// \file trace_hdf5.hpp
/// A trial's trace as a columnar HDF5 file (The HDF Group, "HDF5 File Format Specification", version 3.0;
/// read by h5py and pandas, MATLAB's h5read, R's hdf5r and rhdf5): what a session folder saves
/// (`STEM.trace.h5`), read at the speed of memory where the gzip CSV of before (`trial_csv`, still written by
/// `calligraphy trial --csv` as an export and still read) is read at the speed of its text parser.
///
/// Layout, all at the root, every dataset one-dimensional with one element a servo tick:
///   attributes  format = "calligraphy-trace", version = 1, samples = N
///   t                 time [s]            } integers scaled by 10^decimals: the value is the stored
///   x, y, z           HIP position [m]    } integer / 10^`decimals` (attribute; 6, 7 and 4), the same
///   fx, fy, fz        commanded force [N] } decimals and values as the CSV's text, or float64 (no
///                                           `decimals`) for a column one of whose values an integer
///                                           cannot hold (NaN, beyond 2^53); attribute `unit` "s", "m", "N"
///   state             enum (uint8) SS, AS, CS, WS (paper section 2.3)
///   stroke, element   uint32, 0-based     attempt int32 (1-based, 0 outside any)     rewritten uint8 0/1
/// Chunks of at most 65,536 samples, byte shuffle then deflate (RFC 1950/1951; HDF5's built-in filters, so
/// any HDF5 reader decodes them). The file's first 512 bytes are an HDF5 user block that readers skip; it
/// holds "calligraphy-trace" and the CRC-32 (ISO 3309, as zlib and gzip compute it) and length of the rest,
/// which this library checks before HDF5 parses anything: a damaged or truncated file is refused by name,
/// never handed to HDF5. The header's version fixes the layout and the decimals; the HDF5 attributes say the
/// same to other readers (which scale by them), and once the CRC-32 has matched each is checked (one value,
/// of the class and bounded size written) and must be what this version writes, or the file is refused
/// naming it (DataError: "T.trace.h5: column 'x': attribute /x/decimals is 3, this version writes 7"), so no
/// file reads one way here and another in h5py. Only the exact column types above are read. A file whose
/// CRC-32 was made to match a changed HDF5 structure reaches HDF5's parser, which (1.10.8) may still crash on
/// it.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/recorder.hpp"

namespace calligraphy {

/// The most samples a trace file is written or read with: the ticks a trial can have (kMaxTrialTicks, 10^7:
/// 2.8 hours at 1 kHz), so that a forged length (a small file whose constant columns compress 1000-fold,
/// declaring more samples than any trial) is refused before its columns are allocated.
inline constexpr std::size_t kMaxTraceSamples = static_cast<std::size_t>(kMaxTrialTicks) + 1;

/// A trace's columns as stored, each of length N (`size()`), in SI units.
struct TraceColumns {
  std::vector<double> time_s;
  std::vector<double> x_m, y_m, z_m;     ///< HIP as read from the device [m]
  std::vector<double> fx_n, fy_n, fz_n;  ///< commanded force [N]
  std::vector<std::uint8_t> state;       ///< InteractionState as its number: 0 SS, 1 AS, 2 CS, 3 WS
  std::vector<std::uint32_t> stroke, element;
  std::vector<std::int32_t> attempt;
  std::vector<std::uint8_t> rewritten;
  [[nodiscard]] std::size_t size() const noexcept { return time_s.size(); }
};

/// Which columns a read fills.
enum class TraceColumnSet {
  all,  ///< every column
  pen,  ///< t, x, y, z, fx and fy, what a pen trace's reader takes (pen_trace_csv.hpp); the rest left empty
};

/// The bytes of `trace`'s HDF5 file (see above), the same bytes for the same trace. Values are rounded to
/// the CSV's decimals (kTraceTimeDecimals, kTracePositionDecimals, kTraceForceDecimals, trial_report.hpp).
/// Throws InvalidArgument for more than kMaxTraceSamples samples or a stroke or element index beyond 2^32 -
/// 1, DataError when HDF5 fails (out of memory).
[[nodiscard]] std::string trial_trace_hdf5(const std::vector<TrialSample>& trace);

/// True when `first_bytes` (at least the first 32 bytes of a file) start as a calligraphy trace file.
[[nodiscard]] bool is_trace_hdf5(std::string_view first_bytes) noexcept;

/// Reads every column of a trace file. Refuses, with DataError naming `file`: a missing file, one over
/// `max_file_bytes`, one that is not a calligraphy trace, a damaged or cut file (its CRC-32 or length), a
/// newer version, more than kMaxTraceSamples samples (or more than its bytes could hold), a missing or
/// mistyped column, columns of different lengths, a column whose values are outside the file (an external
/// link, a virtual dataset, HDF5 external storage: no other file is opened) or stored through a filter this
/// HDF5 lacks, samples never written that HDF5 does not fill (undefined), a non-finite time or position, a
/// state beyond WS, a `rewritten` beyond 1.
[[nodiscard]] TraceColumns read_trace_hdf5(const std::filesystem::path& file,
                                           std::uintmax_t max_file_bytes = std::uintmax_t{256} << 20,
                                           TraceColumnSet columns = TraceColumnSet::all);

/// The bytes of a trace file, unparsed, with read_trace_hdf5's refusals of the file itself (missing, not a
/// regular file, over `max_file_bytes`, unreadable): for a reader that hashes the bytes it parses
/// (parse_trace_hdf5), reading the file once.
[[nodiscard]] std::string read_trace_hdf5_bytes(const std::filesystem::path& file,
                                                std::uintmax_t max_file_bytes = std::uintmax_t{256} << 20);

/// As read_trace_hdf5, from the file's bytes; `source` names it in errors.
[[nodiscard]] TraceColumns parse_trace_hdf5(std::string_view bytes, const std::string& source,
                                            TraceColumnSet columns = TraceColumnSet::all);

/// The columns as samples (every column must be read: TraceColumnSet::all), so that `trial_csv` writes the
/// CSV a trial's `--csv` wrote: the same text, byte for byte, for a trace read from its HDF5 file. Throws
/// InvalidArgument when the columns differ in length.
[[nodiscard]] std::vector<TrialSample> trial_samples(const TraceColumns& columns);

}  // namespace calligraphy
