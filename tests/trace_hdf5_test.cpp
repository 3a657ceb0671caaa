#include "calligraphy/report/trace_hdf5.hpp"

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/trial_report.hpp"

using namespace calligraphy;

namespace {

// A pen's trace as devices give it: times that drift from k ms as a clock's sum does, positions of any
// sign and magnitude up to decimetres (not on any grid), forces of a few newtons, every state and index.
std::vector<TrialSample> random_trace(std::size_t samples, std::uint32_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> position(-0.2, 0.2), force(-4.0, 4.0), step(0.0005, 0.0015);
  std::vector<TrialSample> trace(samples);
  double t = 0.0;
  for (std::size_t i = 0; i < samples; ++i) {
    TrialSample& s = trace[i];
    s.time_s = t;
    t += step(random);
    s.position_m = Vec3(position(random), position(random), position(random) * 0.1);
    s.force_n = Vec3(force(random), force(random), force(random));
    s.state = static_cast<InteractionState>(random() % 4);
    s.stroke = random() % 40;
    s.element = random() % 200;
    s.attempt = static_cast<int>(random() % 5);
    s.rewritten = random() % 2 == 1;
  }
  return trace;
}

struct TemporaryFolder {
  std::filesystem::path path;
  TemporaryFolder() {
    static int made = 0;
    path = std::filesystem::temp_directory_path() /
           ("calligraphy_trace_hdf5_" + std::to_string(::getpid()) + "_" + std::to_string(made++));
    std::filesystem::create_directories(path);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    std::ofstream(path / name, std::ios::binary) << bytes;
    return path / name;
  }
};

// Bit for bit: -0.0 and 0.0 differ, NaN equals NaN.
bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

}  // namespace

TEST_CASE("An HDF5 trace reads back to the values its CSV's text parses to, bit for bit", "[trace_hdf5]") {
  const std::vector<TrialSample> trace = random_trace(20'000, 7);
  const TraceColumns c = parse_trace_hdf5(trial_trace_hdf5(trace), "trace");
  REQUIRE(c.size() == trace.size());
  // The CSV of the same trace through the CSV reader: the same decimals, so the same doubles.
  PenTraceCsvOptions options;
  options.read_force = true;
  options.max_pen_down_segments = trace.size();
  const TemporaryFolder folder;
  std::vector<PenTraceRow> rows;
  for_each_pen_trace_row(folder.write("trace.csv", trial_csv(trace)), Placement{}, options,
                         [&rows](const PenTraceRow& row) { rows.push_back(row); });
  REQUIRE(rows.size() == trace.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const PenSample& s = rows[i].sample;
    differing += same_bits(c.time_s[i], s.time_s) && same_bits(c.x_m[i], s.position_m.x()) &&
                         same_bits(c.y_m[i], s.position_m.y()) &&
                         c.state[i] == static_cast<std::uint8_t>(trace[i].state) &&
                         c.stroke[i] == trace[i].stroke && c.element[i] == trace[i].element &&
                         c.attempt[i] == trace[i].attempt && (c.rewritten[i] == 1) == trace[i].rewritten &&
                         std::abs(c.z_m[i] - trace[i].position_m.z()) <= 0.5e-7 &&
                         std::abs(c.fz_n[i] - trace[i].force_n.z()) <= 0.5e-4
                     ? 0
                     : 1;
  }
  CHECK(differing == 0);
  // The pen reader's rows from the HDF5 file are the CSV reader's rows.
  std::size_t differing_rows = 0;
  std::size_t i = 0;
  for_each_pen_trace_row(folder.write("trace.trace.h5", trial_trace_hdf5(trace)), Placement{}, options,
                         [&](const PenTraceRow& row) {
                           const PenTraceRow& csv = rows[i++];
                           differing_rows +=
                               same_bits(row.sample.time_s, csv.sample.time_s) &&
                                       same_bits(row.sample.position_m.x(), csv.sample.position_m.x()) &&
                                       same_bits(row.sample.position_m.y(), csv.sample.position_m.y()) &&
                                       row.sample.pen_down == csv.sample.pen_down &&
                                       same_bits(row.in_plane_force_n, csv.in_plane_force_n)
                                   ? 0
                                   : 1;
                         });
  CHECK(i == trace.size());
  CHECK(differing_rows == 0);
}

TEST_CASE("An HDF5 trace is the same bytes for the same trace, and spans several chunks", "[trace_hdf5]") {
  const std::vector<TrialSample> trace = random_trace(150'000, 3);  // three chunks of 65,536
  const std::string bytes = trial_trace_hdf5(trace);
  CHECK(trial_trace_hdf5(trace) == bytes);
  const TraceColumns c = parse_trace_hdf5(bytes, "trace");
  REQUIRE(c.size() == trace.size());
  CHECK(c.stroke.back() == trace.back().stroke);
  CHECK(std::abs(c.time_s.back() - trace.back().time_s) <= 0.5e-6);
  CHECK(std::abs(c.x_m[70'000] - trace[70'000].position_m.x()) <= 0.5e-7);
}

TEST_CASE("A value no integer holds keeps its column as doubles, exactly", "[trace_hdf5]") {
  std::vector<TrialSample> trace = random_trace(100, 11);
  trace[50].force_n.z() = std::numeric_limits<double>::quiet_NaN();  // a faulted tick, kept as recorded
  trace[60].force_n.x() = 3e20;
  trace[70].position_m.z() = -0.0123456789012345;
  const TraceColumns c = parse_trace_hdf5(trial_trace_hdf5(trace), "trace");
  CHECK(std::isnan(c.fz_n[50]));
  CHECK(c.fx_n[60] == 3e20);
  CHECK(std::abs(c.z_m[70] + 0.0123457) <= 1e-12);  // z is still an integer column: 7 decimals
  CHECK(c.fx_n[61] == trace[61].force_n.x());       // every value of a double column is the value recorded
}

TEST_CASE("An empty trace is a file of no samples", "[trace_hdf5]") {
  const TraceColumns c = parse_trace_hdf5(trial_trace_hdf5({}), "empty");
  CHECK(c.size() == 0);
  CHECK(c.state.empty());
}

TEST_CASE("A damaged, cut or foreign trace file is refused by name before HDF5 reads it", "[trace_hdf5]") {
  const std::string bytes = trial_trace_hdf5(random_trace(3000, 5));
  // Every byte of the header (its text and its zero padding) changed in turn, then bytes through the rest,
  // and cuts at many lengths.
  std::size_t accepted = 0;
  for (std::size_t at = 0; at < bytes.size(); at += at < 512 ? 1 : 97) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x20);
    try {
      (void)parse_trace_hdf5(damaged, "damaged.trace.h5");
      ++accepted;
    } catch (const DataError& e) {
      CHECK_THAT(e.what(), Catch::StartsWith("damaged.trace.h5: "));
    }
  }
  CHECK(accepted == 0);
  for (const std::size_t length : {std::size_t{0}, std::size_t{10}, std::size_t{511}, std::size_t{512},
                                   std::size_t{600}, bytes.size() / 2, bytes.size() - 1}) {
    CHECK_THROWS_AS(parse_trace_hdf5(bytes.substr(0, length), "cut"), DataError);
  }
  CHECK_THROWS_WITH(parse_trace_hdf5(bytes + "x", "longer"), Catch::Contains("bytes added"));
  CHECK_THROWS_WITH(parse_trace_hdf5("t,x,y\n0,0,0\n", "text.csv"),
                    Catch::Contains("not a calligraphy trace"));
  std::string newer = bytes;
  newer.replace(newer.find("version 1"), 9, "version 2");
  CHECK_THROWS_WITH(parse_trace_hdf5(newer, "newer"),
                    Catch::Contains("version 2") && Catch::Contains("newer"));
}

TEST_CASE("A trace file over the size limit or missing is refused by name", "[trace_hdf5]") {
  const TemporaryFolder folder;
  const auto file = folder.write("big.trace.h5", trial_trace_hdf5(random_trace(1000, 9)));
  CHECK_THROWS_WITH(read_trace_hdf5(file, 1000), Catch::Contains("big.trace.h5") && Catch::Contains("limit"));
  CHECK_THROWS_WITH(read_trace_hdf5(folder.path / "none.trace.h5"), Catch::Contains("none.trace.h5"));
  CHECK(read_trace_hdf5(file).size() == 1000);
}
