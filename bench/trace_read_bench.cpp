// Reading a trial's pen trace: samples per second (items_per_second) of the one trace parser
// (report/pen_trace_csv.hpp) on a trace of about 1,000,000 rows written by `trial_csv`, the writer of
// `trial --csv` and of a session's trials/*.csv.gz: parsed from memory, read from a plain file and read
// from the gzip file a session saves (decompressed on the way), as `calligraphy report` reads it.
// Run a Release build: build/bin/trace_read_bench --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true   (the median row is the figure to quote)
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "report/compressed_text.hpp"

namespace {

using namespace calligraphy;

constexpr std::size_t kRows = 1'000'000;
constexpr double kPaperZ = 0.01;

// A pen writing at 1 kHz: loops of a few centimetres on the 0.023 mm encoder steps of a Phantom Desktop,
// lifted now and then, with guidance forces of tenths of a newton, so that the fields have the lengths and
// signs of a session's trials (about 64 bytes a row; times drift from k ms as a device clock's sum does).
const std::vector<TrialSample>& trace_samples() {
  static const std::vector<TrialSample> samples = [] {
    std::vector<TrialSample> trace(kRows);
    double t = 0.0;
    for (std::size_t i = 0; i < kRows; ++i) {
      const double phase = static_cast<double>(i) * 0.0037;
      TrialSample& s = trace[i];
      s.time_s = t;
      t += 0.001;
      const auto step = [](double m) { return std::round(m / 0.000023) * 0.000023; };
      s.position_m = Vec3(step(0.02 * std::sin(phase)), step(-0.015 * std::cos(1.3 * phase)),
                          kPaperZ + step((i / 700) % 3 == 0 ? 0.003 : -0.0008 * std::sin(0.01 * phase)));
      s.force_n = Vec3(0.4 * std::cos(2.1 * phase), -0.25 * std::sin(phase), 1.5 + std::sin(0.7 * phase));
      s.state = (i / 700) % 3 == 0 ? InteractionState::separation : InteractionState::writing;
      s.stroke = i / 5000;
      s.element = (i / 100) % 20;
      s.attempt = 1;
    }
    return trace;
  }();
  return samples;
}

const std::string& trace_text() {
  static const std::string text = trial_csv(trace_samples());
  return text;
}

// How the report reads a trial's trace (study/session_reader.cpp): z against the paper, the in-plane force.
PenTraceCsvOptions report_options() {
  PenTraceCsvOptions options;
  options.paper_z_m = kPaperZ;
  options.read_force = true;
  options.max_samples = kRows + 1;
  options.max_pen_down_segments = kRows;
  return options;
}

enum class Format { plain, gzip, hdf5, hdf5_trial };
constexpr std::size_t kTrialRows = 10'000;  // a trial of 10 s at 1 kHz, as a session saves

// The trace written to a file of its own under the temporary directory (CSV plain or gzip, HDF5 whole or
// its first 10 s), removed at exit.
const std::filesystem::path& trace_file(Format format) {
  static const std::filesystem::path folder = [] {
    const auto made = std::filesystem::temp_directory_path() /
                      ("calligraphy_trace_read_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(made);
    std::ofstream(made / "trace.csv", std::ios::binary) << trace_text();
    std::ofstream(made / "trace.csv.gz", std::ios::binary) << gzip_text(trace_text());
    std::ofstream(made / "trace.trace.h5", std::ios::binary) << trial_trace_hdf5(trace_samples());
    const std::vector<TrialSample> trial(trace_samples().begin(), trace_samples().begin() + kTrialRows);
    std::ofstream(made / "trial.trace.h5", std::ios::binary) << trial_trace_hdf5(trial);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                                      ("calligraphy_trace_read_bench_" + std::to_string(::getpid())),
                                  ignored);
    });
    return made;
  }();
  static const std::filesystem::path files[] = {folder / "trace.csv", folder / "trace.csv.gz",
                                                folder / "trace.trace.h5", folder / "trial.trace.h5"};
  return files[static_cast<int>(format)];
}

void trace_parse_memory(benchmark::State& state) {
  const std::string& text = trace_text();
  const PenTraceCsvOptions options = report_options();
  for (auto _ : state) benchmark::DoNotOptimize(parse_pen_trace_csv(text, "trace", Placement{}, options));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kRows));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}

// The columns a per-trial page keeps of a trace (study/session_reader.cpp), kept between reads.
struct PageColumns {
  std::vector<double> time_s, force_n;
  std::vector<Vec2> position_m;
  std::vector<bool> pen_down;
  void read(const std::filesystem::path& file, const PenTraceCsvOptions& options) {
    time_s.clear();
    force_n.clear();
    position_m.clear();
    pen_down.clear();
    for_each_pen_trace_row(file, Placement{}, options, [this](const PenTraceRow& row) {
      time_s.push_back(row.sample.time_s);
      position_m.push_back(row.sample.position_m);
      pen_down.push_back(row.sample.pen_down);
      force_n.push_back(row.in_plane_force_n);
    });
  }
};

// A file streamed row by row into the columns the per-trial pages keep, as the report does.
void read_file(benchmark::State& state, Format format) {
  const std::filesystem::path& file = trace_file(format);
  const std::size_t rows = format == Format::hdf5_trial ? kTrialRows : kRows;
  const PenTraceCsvOptions options = report_options();
  PageColumns columns;
  for (auto _ : state) {
    columns.read(file, options);
    benchmark::DoNotOptimize(columns.time_s.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rows));
  state.counters["file_bytes"] = static_cast<double>(std::filesystem::file_size(file));
}

void trace_read_plain_file(benchmark::State& state) { read_file(state, Format::plain); }
void trace_read_gzip_file(benchmark::State& state) { read_file(state, Format::gzip); }
void trace_read_hdf5_file(benchmark::State& state) { read_file(state, Format::hdf5); }
void trace_read_hdf5_trial_file(benchmark::State& state) { read_file(state, Format::hdf5_trial); }

// Every column of the HDF5 file into memory (read_trace_hdf5), as Python's Study.samples reads it.
void trace_read_hdf5_columns(benchmark::State& state) {
  const std::filesystem::path& file = trace_file(Format::hdf5);
  for (auto _ : state) benchmark::DoNotOptimize(read_trace_hdf5(file).size());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kRows));
}

// Every trace file under the folder CALLIGRAPHY_BENCH_STUDY (a study made by bench/study_scale.sh: real
// simulated writing, with its motor noise; HDF5, or the gzip CSV of a study made before), read as the report
// reads them; skipped when it is not set.
void trace_read_study_files(benchmark::State& state) {
  const char* folder = std::getenv("CALLIGRAPHY_BENCH_STUDY");
  if (folder == nullptr) {
    state.SkipWithError(
        "set CALLIGRAPHY_BENCH_STUDY to a study folder (bench/study_scale.sh) to time its traces");
    return;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    const std::string name = entry.path().string();
    // a study's traces, HDF5 or, in a folder of before, gzip CSV (not its tables)
    if (name.ends_with(".trace.h5") ||
        (name.ends_with(".csv.gz") && name.find("/trials/") != std::string::npos))
      files.push_back(entry.path());
  }
  PenTraceCsvOptions options = report_options();
  options.paper_z_m = 0.0;  // pen contact is not what is timed
  PageColumns columns;
  std::size_t samples = 0;
  for (auto _ : state) {
    for (const std::filesystem::path& file : files) {
      columns.read(file, options);
      samples += columns.time_s.size();
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(samples));
  state.counters["files"] = static_cast<double>(files.size());
  state.counters["samples_per_file"] =
      files.empty() ? 0.0
                    : static_cast<double>(samples) / static_cast<double>(state.iterations() * files.size());
}

}  // namespace

BENCHMARK(trace_parse_memory)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_plain_file)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_gzip_file)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_hdf5_file)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_hdf5_trial_file)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_hdf5_columns)->Unit(benchmark::kMillisecond);
BENCHMARK(trace_read_study_files)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
