#include "calligraphy/report/pen_trace_csv.hpp"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"

using namespace calligraphy;

namespace {

Placement test_placement() {
  Placement p;
  p.origin_m = Vec2(-0.03, -0.0225);
  p.metres_per_unit = 0.06 / 1024.0;
  return p;
}

// A file in a folder of its own under the temporary directory, removed with the folder.
struct TemporaryFile {
  std::filesystem::path folder;
  std::filesystem::path path;
  explicit TemporaryFile(const std::string& text, const std::string& name = "trace.csv") {
    static int made = 0;  // unique within the process; the process id makes it unique across processes
    folder = std::filesystem::temp_directory_path() /
             ("calligraphy_pen_trace_csv_" + std::to_string(::getpid()) + "_" + std::to_string(made++));
    std::filesystem::create_directories(folder);
    path = folder / name;
    std::ofstream(path, std::ios::binary) << text;
  }
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  }
};

}  // namespace

TEST_CASE("A metres trace with a pen column is read by header name", "[pen_trace_csv]") {
  const std::string text =
      "# recorded at 1 kHz\r\n"
      "y, t ,pen,x,force\r\n"
      "0.002,0.000,0,0.001,9\r\n"
      "\r\n"
      "0.003,0.001,1,0.0015,9\r\n"
      "0.004,0.001,1,0.002,9\r\n";
  const auto samples = parse_pen_trace_csv(text, "inline", test_placement());
  REQUIRE(samples.size() == 3);
  CHECK(samples[0].time_s == 0.0);
  CHECK(samples[0].position_m == Vec2(0.001, 0.002));
  CHECK_FALSE(samples[0].pen_down);
  CHECK(samples[1].pen_down);
  CHECK(samples[2].time_s == 0.001);  // equal times are allowed
  CHECK(samples[2].position_m == Vec2(0.002, 0.004));
}

TEST_CASE("A column is read by its name in the trace column table as by its file name", "[pen_trace_csv]") {
  // Python's DataFrames name the columns with their units (trace_columns.hpp): the same samples.
  const std::string rows = "0,0.001,0.002,0\n0.001,0.0015,0.003,0\n0.002,0.002,0.004,0.001\n";
  const auto by_file_name = parse_pen_trace_csv("t,x,y,z\n" + rows, "files", test_placement());
  const auto by_name = parse_pen_trace_csv("t_s,x_m,y_m,z_m\n" + rows, "names", test_placement());
  REQUIRE(by_name.size() == 3);
  REQUIRE(by_name.size() == by_file_name.size());
  for (std::size_t i = 0; i < by_name.size(); ++i) {
    CHECK(by_name[i].time_s == by_file_name[i].time_s);
    CHECK(by_name[i].position_m == by_file_name[i].position_m);
    CHECK(by_name[i].pen_down == by_file_name[i].pen_down);
  }
  CHECK_FALSE(by_name[2].pen_down);
  // One column named both ways is named twice.
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,z,t_s\n0,0,0,0,0\n", "both.csv", test_placement()),
                    Catch::Contains("both.csv:1") && Catch::Contains("'t_s' appears twice"));
}

TEST_CASE("A z column sets pen contact by the threshold", "[pen_trace_csv]") {
  const std::string text = "t,x,y,z\n0,0,0,0.0004\n0.001,0,0,0.0005\n0.002,0,0,0.0006\n0.003,0,0,-0.001\n";
  const auto samples = parse_pen_trace_csv(text, "inline", test_placement());
  REQUIRE(samples.size() == 4);
  CHECK(samples[0].pen_down);
  CHECK(samples[1].pen_down);  // z <= 0.5 mm
  CHECK_FALSE(samples[2].pen_down);
  CHECK(samples[3].pen_down);  // below the paper plane: pressing
  PenTraceCsvOptions strict;
  strict.contact_threshold_m = 0.0;
  CHECK_FALSE(parse_pen_trace_csv(text, "inline", test_placement(), strict)[0].pen_down);
}

TEST_CASE("A pen column takes the number 1 or 0 however another program spells it", "[pen_trace_csv]") {
  // numpy.savetxt writes 1.000000000000000000e+00, pandas a float column's 1.0: the numbers 1 and 0.
  const auto samples = parse_pen_trace_csv(
      "t,x,y,pen\n0,0,0,1.0\n0.001,0,0,0.0\n0.002,0,0,1.000000000000000000e+00\n0.003,0,0,0e0\n0.004,0,0,-"
      "0\n",
      "spellings.csv", test_placement());
  REQUIRE(samples.size() == 5);
  CHECK(samples[0].pen_down);
  CHECK_FALSE(samples[1].pen_down);
  CHECK(samples[2].pen_down);
  CHECK_FALSE(samples[3].pen_down);
  CHECK_FALSE(samples[4].pen_down);
  for (const char* value : {"0.5", "1.0000001", "2e0", "nan", "inf", "true", "0x1", ""}) {
    INFO(value);
    CHECK_THROWS_WITH(
        parse_pen_trace_csv(std::string("t,x,y,pen\n0,0,0,") + value + "\n", "odd.csv", test_placement()),
        Catch::Contains("odd.csv:2") && Catch::Contains("pen must be 1 (down) or 0 (up)"));
  }
}

TEST_CASE("UTF-16 text and lines ending in CR alone are refused saying so", "[pen_trace_csv]") {
  CHECK_THROWS_WITH(parse_pen_trace_csv(std::string("\xFF\xFEt\0,\0x\0", 8), "excel.txt", test_placement()),
                    Catch::Contains("excel.txt:1") && Catch::Contains("UTF-16"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\r0,0,0,1\r0.001,0,0,1\r", "mac.csv", test_placement()),
                    Catch::Contains("mac.csv:1") && Catch::Contains("CR alone"));
  // A UTF-8 byte-order mark and CR LF are still read.
  CHECK(parse_pen_trace_csv("\xEF\xBB\xBFt,x,y,pen\r\n0,0,0,1\r\n", "bom.csv", test_placement()).size() == 1);
}

TEST_CASE("A JSON document or markup in a trace's place is named as what it is", "[pen_trace_csv]") {
  // A trial record (trial --json), one line or pretty-printed, with a byte-order mark; an SVG drawing.
  for (const char* text :
       {"{\"character\": \"一\", \"t\": 1}\n", "{\n  \"t\": 1\n}\n", "\xEF\xBB\xBF [1, 2]\n"}) {
    CHECK_THROWS_WITH(parse_pen_trace_csv(text, "record.csv", test_placement()),
                      Catch::StartsWith("record.csv:1: a JSON document, not a trace"));
  }
  CHECK_THROWS_WITH(
      parse_pen_trace_csv("<svg xmlns=\"http://www.w3.org/2000/svg\">\n", "t.csv", test_placement()),
      Catch::StartsWith("t.csv:1: markup"));
}

TEST_CASE("Data units are converted with the placement", "[pen_trace_csv]") {
  PenTraceCsvOptions options;
  options.units = TraceUnits::data;
  const Placement placement = test_placement();
  const auto samples =
      parse_pen_trace_csv("t,x,y,pen\n0,512,388,1\n0.1,0,900,1\n", "inline", placement, options);
  REQUIRE(samples.size() == 2);
  CHECK(samples[0].position_m.isApprox(placement.to_paper(Vec2(512.0, 388.0))));
  CHECK(samples[1].position_m.isApprox(placement.origin_m + Vec2(0.0, 900.0 * 0.06 / 1024.0)));
  CHECK(parse_trace_units("data") == TraceUnits::data);
  CHECK(parse_trace_units("metres") == TraceUnits::metres);
  CHECK_THROWS_WITH(parse_trace_units("mm"), Catch::Contains("'mm'"));
}

TEST_CASE("Malformed traces name the source, line and column", "[pen_trace_csv]") {
  const Placement p = test_placement();
  CHECK_THROWS_WITH(
      parse_pen_trace_csv("t,x,y,pen\n0,0,0,1\n0.1,abc,0,1\n", "a.csv", p),
      Catch::Contains("a.csv:3") && Catch::Contains("column 2 (x)") && Catch::Contains("'abc'"));
  CHECK_THROWS_WITH(
      parse_pen_trace_csv("t,x,y,pen\n0,0,0,1\n0.1,0,nan,1\n", "a.csv", p),
      Catch::Contains("a.csv:3") && Catch::Contains("column 3 (y)") && Catch::Contains("finite"));
  CHECK_THROWS_WITH(
      parse_pen_trace_csv("t,x,y,pen\n0,1e400,0,1\n", "a.csv", p),
      Catch::Contains("a.csv:2") && Catch::Contains("column 2 (x)") && Catch::Contains("range"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\n0,0,0,2\n", "a.csv", p),
                    Catch::Contains("a.csv:2") && Catch::Contains("column 4 (pen)"));
  CHECK_THROWS_WITH(
      parse_pen_trace_csv("t,x,y,pen\n0.2,0,0,1\n0.1,0,0,1\n", "a.csv", p),
      Catch::Contains("a.csv:3") && Catch::Contains("column 1 (t)") && Catch::Contains("backwards"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\n0,0,0\n", "a.csv", p),
                    Catch::Contains("a.csv:2") && Catch::Contains("3 fields"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,pen\n0,0,1\n", "a.csv", p), Catch::Contains("'y'"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y\n0,0,0\n", "a.csv", p), Catch::Contains("neither"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen,z\n", "a.csv", p), Catch::Contains("both"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,x,y,pen\n", "a.csv", p), Catch::Contains("twice"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("# only a comment\n", "a.csv", p), Catch::Contains("no header"));
  // A field in double quotes (RFC 4180, as spreadsheets write every field) is the text between them; a quote
  // that does not enclose its field, or one inside it, stays and is refused.
  const auto quoted = parse_pen_trace_csv("\"t\",\"x\",\"y\",\"pen\"\n\"0\",\"0.001\",0,\"1\"\n", "a.csv", p);
  const auto plain = parse_pen_trace_csv("t,x,y,pen\n0,0.001,0,1\n", "a.csv", p);
  REQUIRE(quoted.size() == 1);
  REQUIRE(plain.size() == 1);
  CHECK(quoted[0].position_m == plain[0].position_m);
  CHECK(quoted[0].pen_down);
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\n0,\"1,0,1\n", "a.csv", p),
                    Catch::Contains("a.csv:2") && Catch::Contains("column 2 (x)"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\n0,\"1\"2\",0,1\n", "a.csv", p),
                    Catch::Contains("a.csv:2") && Catch::Contains("column 2 (x)"));
  CHECK_THROWS_WITH(parse_pen_trace_csv("\"t,x,y,pen\n0,0,0,1\n", "a.csv", p), Catch::Contains("'t'"));
  // Header only: an empty trace.
  CHECK(parse_pen_trace_csv("t,x,y,pen\n", "a.csv", p).empty());
}

TEST_CASE("Files are read whole, regular and bounded in size", "[pen_trace_csv]") {
  const std::string text = "t,x,y,pen\n0,0.001,0.002,1\n0.001,0.002,0.002,1\n";
  const TemporaryFile file(text);
  const auto samples = read_pen_trace_csv(file.path, test_placement());
  REQUIRE(samples.size() == 2);
  CHECK(samples[1].position_m == Vec2(0.002, 0.002));
  PenTraceCsvOptions small;
  small.max_file_bytes = text.size() - 1;
  CHECK_THROWS_WITH(read_pen_trace_csv(file.path, test_placement(), small),
                    Catch::Contains(file.path.string()) && Catch::Contains("limit"));
  CHECK_THROWS_WITH(read_pen_trace_csv(file.folder, test_placement()), Catch::Contains("not a regular file"));
  CHECK_THROWS_WITH(read_pen_trace_csv(file.folder / "missing.csv", test_placement()),
                    Catch::Contains("missing.csv") && Catch::Contains("no such file"));
  const TemporaryFile bad("t,x,y,pen\n0,0,0,1\n0.1,0,0,yes\n", "bad.csv");
  CHECK_THROWS_WITH(read_pen_trace_csv(bad.path, test_placement()),
                    Catch::Contains("bad.csv:3") && Catch::Contains("column 4 (pen)"));
}

TEST_CASE("A UTF-8 byte-order mark before the header is skipped", "[pen_trace_csv]") {
  // As spreadsheet programs write a CSV file ("CSV UTF-8"), with CR LF.
  const std::string text = "\xEF\xBB\xBFt,x,y,pen\r\n0,0.001,0.002,1\r\n0.001,0.002,0.003,1\r\n";
  const auto samples = parse_pen_trace_csv(text, "inline", test_placement());
  REQUIRE(samples.size() == 2);
  CHECK(samples[1].position_m == Vec2(0.002, 0.003));
  const TemporaryFile file(text);
  CHECK(read_pen_trace_csv(file.path, test_placement()).size() == 2);
  // Only at the start: elsewhere it is part of a field, and refused as such.
  CHECK_THROWS_WITH(parse_pen_trace_csv("t,x,y,pen\n\xEF\xBB\xBF"
                                        "0,0,0,1\n",
                                        "inline", test_placement()),
                    Catch::Contains("inline:2") && Catch::Contains("not a number"));
}

TEST_CASE("A trace with more pen-down segments than the limit is refused while reading", "[pen_trace_csv]") {
  PenTraceCsvOptions options;
  options.max_pen_down_segments = 3;
  std::string text = "t,x,y,pen\n";
  for (int k = 0; k < 3; ++k) {
    text += std::to_string(3 * k) + ",0,0,1\n" + std::to_string(3 * k + 1) + ",0,0,1\n" +
            std::to_string(3 * k + 2) + ",0,0,0\n";
  }
  CHECK(parse_pen_trace_csv(text, "inline", test_placement(), options).size() == 9);
  text += "9,0,0,1\n10,0,0,1\nnot read, so not refused as a row\n";
  CHECK_THROWS_WITH(parse_pen_trace_csv(text, "inline", test_placement(), options),
                    Catch::StartsWith("inline:11: ") && Catch::Contains("more than 3 pen-down segments"));
  CHECK(PenTraceCsvOptions{}.max_pen_down_segments == kMaxScoredSegments);
  options.max_pen_down_segments = 0;
  CHECK_THROWS_AS(parse_pen_trace_csv("t,x,y,pen\n", "inline", test_placement(), options), InvalidArgument);
}

TEST_CASE("The reader reports its progress through the text", "[pen_trace_csv]") {
  PenTraceCsvOptions options;
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  options.progress = [&calls](std::size_t parsed, std::size_t total) { calls.emplace_back(parsed, total); };
  const std::string text = "t,x,y,pen\n0,0,0,1\n";
  parse_pen_trace_csv(text, "inline", test_placement(), options);
  REQUIRE_FALSE(calls.empty());
  CHECK(calls.back() == std::pair{text.size(), text.size()});
}

TEST_CASE("A trace with more samples than the limit is refused while reading", "[pen_trace_csv]") {
  PenTraceCsvOptions options;
  options.max_samples = 3;
  const std::string three = "t,x,y,pen\n0,0,0,1\n1,0,0,1\n2,0,0,1\n";
  CHECK(parse_pen_trace_csv(three, "inline", test_placement(), options).size() == 3);
  CHECK_THROWS_WITH(parse_pen_trace_csv(three + "3,0,0,1\nnot read\n", "inline", test_placement(), options),
                    Catch::StartsWith("inline:5: ") && Catch::Contains("more than 3 samples"));
  CHECK(PenTraceCsvOptions{}.max_samples == 1'000'000);
  options.max_samples = 0;
  CHECK_THROWS_AS(parse_pen_trace_csv(three, "inline", test_placement(), options), InvalidArgument);
}

TEST_CASE("A file is read in blocks as the same text parsed whole", "[pen_trace_csv]") {
  // Over 1 MiB blocks: lines cross block ends; CR LF, a byte-order mark and no LF after the last line.
  std::string text = "\xEF\xBB\xBFt,x,y,pen\r\n";
  for (int i = 0; i < 150000; ++i) {
    text += std::to_string(i) + ".5," + std::to_string(i % 97) + "e-4," + std::to_string(i % 89) + "e-4," +
            (i % 100 == 0 ? "0" : "1") + "\r\n";
  }
  text += "150000,0,0,1";
  REQUIRE(text.size() > (std::size_t{3} << 20));
  const TemporaryFile file(text);
  PenTraceCsvOptions options;
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  options.progress = [&calls](std::size_t parsed, std::size_t total) { calls.emplace_back(parsed, total); };
  const auto read = read_pen_trace_csv(file.path, test_placement(), options);
  const auto parsed = parse_pen_trace_csv(text, "inline", test_placement());
  REQUIRE(read.size() == 150001);
  REQUIRE(read.size() == parsed.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    REQUIRE(read[i].time_s == parsed[i].time_s);
    REQUIRE(read[i].position_m == parsed[i].position_m);
    REQUIRE(read[i].pen_down == parsed[i].pen_down);
  }
  REQUIRE(calls.size() > 2);
  CHECK(std::is_sorted(calls.begin(), calls.end()));
  CHECK(calls.back() == std::pair{text.size(), text.size()});
  // An error past the first block names its line.
  std::string bad = text;
  bad.replace(bad.find("\r\n120000.5,") + 2, 1, "x");
  const TemporaryFile bad_file(bad);
  CHECK_THROWS_WITH(read_pen_trace_csv(bad_file.path, test_placement()),
                    Catch::Contains("trace.csv:120002:") && Catch::Contains("not a number"));
}

namespace {

// `text` gzip-compressed into `path` by zlib's own file interface (as `gzip` writes it).
void write_gzip(const std::filesystem::path& path, const std::string& text) {
  gzFile out = gzopen(path.c_str(), "wb");
  REQUIRE(out != nullptr);
  REQUIRE(gzwrite(out, text.data(), static_cast<unsigned>(text.size())) == static_cast<int>(text.size()));
  REQUIRE(gzclose(out) == Z_OK);
}

}  // namespace

TEST_CASE("A gzip-compressed trace reads as its text, and a damaged one is named", "[pen_trace_csv]") {
  std::string text = "t,x,y,pen\n";
  for (int i = 0; i < 20000; ++i) {
    text += std::to_string(i * 0.001) + "," + std::to_string(0.0001 * (i % 97)) + ",0.002," +
            (i % 500 < 400 ? "1" : "0") + "\n";
  }
  const TemporaryFile plain(text);
  const TemporaryFile compressed("", "trace.csv.gz");
  write_gzip(compressed.path, text);
  const auto expected = read_pen_trace_csv(plain.path, test_placement());
  const auto read = read_pen_trace_csv(compressed.path, test_placement());
  REQUIRE(read.size() == expected.size());
  REQUIRE(read.size() == 20000);
  for (std::size_t i = 0; i < read.size(); ++i) {
    CHECK(read[i].time_s == expected[i].time_s);
    CHECK(read[i].position_m == expected[i].position_m);
    CHECK(read[i].pen_down == expected[i].pen_down);
  }
  // Cut short: the end of the stream is missing.
  const auto size = std::filesystem::file_size(compressed.path);
  std::filesystem::resize_file(compressed.path, size / 2);
  CHECK_THROWS_WITH(read_pen_trace_csv(compressed.path, test_placement()),
                    Catch::Contains("trace.csv.gz") && Catch::Contains("gzip"));
  // A gzip header followed by what is not deflate.
  const TemporaryFile damaged(
      std::string("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03", 10) + "not deflate data", "damaged.csv.gz");
  CHECK_THROWS_WITH(read_pen_trace_csv(damaged.path, test_placement()), Catch::Contains("damaged.csv.gz"));
  // A small file whose text is over the limit is refused as it decompresses, not read whole.
  const TemporaryFile bomb("", "bomb.csv.gz");
  std::string bomb_text = "t,x,y,pen\n";
  bomb_text.append(std::size_t{4} << 20, '#');  // appended, not summed: GCC 12 warns of a false overflow
  bomb_text += "\n";
  write_gzip(bomb.path, bomb_text);
  REQUIRE(std::filesystem::file_size(bomb.path) < 64 * 1024);
  PenTraceCsvOptions small;
  small.max_file_bytes = 1 << 20;
  CHECK_THROWS_WITH(read_pen_trace_csv(bomb.path, test_placement(), small),
                    Catch::Contains("bomb.csv.gz") && Catch::Contains("the limit"));
}

TEST_CASE("A trial's trace is written to a fixed precision in the fewest characters", "[pen_trace_csv]") {
  std::vector<TrialSample> trace(3);
  double t = 0.0;
  for (TrialSample& s : trace) {  // time summed tick by tick, as a device clock drifts from k ms
    s.time_s = t;
    t += 0.001;
  }
  trace[1].position_m = Vec3(-0.011845, 0.0104650000000001, -0.0);
  trace[1].force_n = Vec3(-0.00980123, 0.5, 1.0 / 3.0);
  trace[2].position_m = Vec3(0.123456789, -1e-9, 0.02001);
  trace[0].force_n = Vec3(0.0, 0.0, 1e300);  // a fault's value: round-trip text, the row within bounds
  trace[2].state = InteractionState::writing;
  trace[2].stroke = 2;
  trace[2].attempt = 3;  // the third attempt at its stroke, written again later
  trace[2].rewritten = true;
  const std::string csv = trial_csv(trace);
  CHECK(csv ==
        "t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten\n"
        "0,0,0,0,0,0,1e+300,SS,0,0,0,0\n"
        "0.001,-0.011845,0.010465,0,-0.0098,0.5,0.3333,SS,0,0,0,0\n"
        "0.002,0.1234568,0,0.02001,0,0,0,WS,2,0,3,1\n");
  // Read back, every value within half its last decimal of the one written.
  const auto samples = parse_pen_trace_csv(csv, "trace", test_placement());
  REQUIRE(samples.size() == trace.size());
  for (std::size_t i = 0; i < trace.size(); ++i) {
    CHECK(std::abs(samples[i].time_s - trace[i].time_s) <= 0.5e-6);
    CHECK((samples[i].position_m - trace[i].position_m.head<2>()).cwiseAbs().maxCoeff() <= 0.5e-7);
  }
}

TEST_CASE("A trial's trace is streamed row by row with its in-plane force over a raised paper",
          "[pen_trace_csv]") {
  std::vector<TrialSample> trace(3);
  const double paper_z_m = 0.01;  // the paper 10 mm up in device space
  for (std::size_t i = 0; i < trace.size(); ++i) {
    trace[i].time_s = 0.001 * static_cast<double>(i);
    trace[i].position_m = Vec3(0.001 * static_cast<double>(i), 0.002, paper_z_m);
    trace[i].force_n = Vec3(0.3, -0.4, 2.0);
  }
  trace[1].position_m.z() = paper_z_m + 0.002;  // lifted 2 mm: above the 0.5 mm contact threshold
  const TemporaryFile file(trial_csv(trace));
  PenTraceCsvOptions options;
  options.paper_z_m = paper_z_m;
  options.read_force = true;
  std::vector<PenTraceRow> rows;
  for_each_pen_trace_row(file.path, test_placement(), options,
                         [&rows](const PenTraceRow& r) { rows.push_back(r); });
  REQUIRE(rows.size() == 3);
  CHECK(rows[0].sample.pen_down);
  CHECK_FALSE(rows[1].sample.pen_down);
  CHECK(rows[2].sample.pen_down);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    CHECK(rows[i].in_plane_force_n == Approx(0.5).margin(1e-12));  // |(0.3, -0.4)|, fz left out
    CHECK(rows[i].sample.time_s == trace[i].time_s);
  }
  // The same rows as the samples read whole; without the paper's height every sample is above the paper.
  const std::vector<PenSample> whole = read_pen_trace_csv(file.path, test_placement(), options);
  REQUIRE(whole.size() == rows.size());
  for (std::size_t i = 0; i < whole.size(); ++i) CHECK(whole[i].pen_down == rows[i].sample.pen_down);
  for (const PenSample& s : read_pen_trace_csv(file.path, test_placement())) CHECK_FALSE(s.pen_down);
  // Force asked of a trace without it names the missing column; a bad force value names its column.
  const TemporaryFile plain("t,x,y,pen\n0,0,0,1\n");
  CHECK_THROWS_WITH(read_pen_trace_csv(plain.path, test_placement(), options), Catch::Contains("'fx'"));
  const TemporaryFile bad("t,x,y,z,fx,fy\n0,0,0,0,0.1,nan\n");
  CHECK_THROWS_WITH(read_pen_trace_csv(bad.path, test_placement(), options),
                    Catch::Contains("trace.csv:2:") && Catch::Contains("(fy)"));
  options.paper_z_m = std::nan("");
  CHECK_THROWS_AS(read_pen_trace_csv(file.path, test_placement(), options), InvalidArgument);
}

TEST_CASE("A trial's trace reads to the same samples by the fast way and the general one",
          "[pen_trace_csv]") {
  // Rows of plain decimals go the fast way (one pass over the line); the same rows with their fields padded
  // with blanks, a comment between them and CR LF ends go the general way (fields split and trimmed, each
  // number through parse_finite_double): every sample must be the same double for double.
  std::vector<TrialSample> trace(20000);
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> metres(-0.1, 0.1), newtons(-3.0, 3.0), step(0.0, 0.002);
  double t = 0.0;
  for (TrialSample& s : trace) {
    s.time_s = t;
    t += step(random);
    s.position_m = Vec3(metres(random), metres(random), 0.01 + metres(random) / 100.0);
    s.force_n = Vec3(newtons(random), newtons(random), newtons(random));
  }
  trace[6].force_n.x() = 1e15;  // a fault's value, written in the shortest round-trip text: the general way
  const std::string fast = trial_csv(trace);
  std::string general;
  for (std::size_t start = 0; start < fast.size();) {
    const std::size_t end = fast.find('\n', start);
    std::string line = fast.substr(start, end - start);
    for (std::size_t comma = 0; (comma = line.find(',', comma)) != std::string::npos; comma += 3)
      line.replace(comma, 1, " , ");
    general += " " + line + " \r\n# a comment\r\n";
    start = end + 1;
  }
  for (const TraceUnits units : {TraceUnits::metres, TraceUnits::data}) {
    PenTraceCsvOptions options;
    options.units = units;
    options.paper_z_m = 0.01;
    options.read_force = true;
    std::vector<PenTraceRow> by_fast, by_general;
    const TemporaryFile fast_file(fast), general_file(general);
    for_each_pen_trace_row(fast_file.path, test_placement(), options,
                           [&by_fast](const PenTraceRow& r) { by_fast.push_back(r); });
    for_each_pen_trace_row(general_file.path, test_placement(), options,
                           [&by_general](const PenTraceRow& r) { by_general.push_back(r); });
    REQUIRE(by_fast.size() == trace.size());
    REQUIRE(by_general.size() == trace.size());
    for (std::size_t i = 0; i < trace.size(); ++i) {
      INFO(i);
      const PenTraceRow& a = by_fast[i];
      const PenTraceRow& b = by_general[i];
      CHECK(std::bit_cast<std::uint64_t>(a.sample.time_s) == std::bit_cast<std::uint64_t>(b.sample.time_s));
      CHECK(std::bit_cast<std::uint64_t>(a.sample.position_m.x()) ==
            std::bit_cast<std::uint64_t>(b.sample.position_m.x()));
      CHECK(std::bit_cast<std::uint64_t>(a.sample.position_m.y()) ==
            std::bit_cast<std::uint64_t>(b.sample.position_m.y()));
      CHECK(a.sample.pen_down == b.sample.pen_down);
      CHECK(std::bit_cast<std::uint64_t>(a.in_plane_force_n) ==
            std::bit_cast<std::uint64_t>(b.in_plane_force_n));
    }
    CHECK(by_fast[6].in_plane_force_n == Approx(1e15));
  }
}

TEST_CASE("A row the fast way cannot take is refused as before, naming its line and column",
          "[pen_trace_csv]") {
  const Placement p = test_placement();
  const std::string header = "t,x,y,pen\n0,0.001,0.002,1\n";
  for (const auto& [row, named] :
       std::vector<std::pair<std::string, std::string>>{{"0.1,0.5x,0,1", "column 2 (x)"},
                                                        {"0.1,0,0,1,", "5 fields"},
                                                        {"0.1,0,0", "3 fields"},
                                                        {"0.1,0,0,10", "column 4 (pen)"},
                                                        {"0.1,0,0.1.2,1", "column 3 (y)"},
                                                        {"0.1,0,1e999,1", "column 3 (y)"},
                                                        {std::string("0.1,0\0,0,1", 10), "column 2 (x)"},
                                                        {"-0.5,0,0,1", "backwards"}}) {
    INFO(row);
    CHECK_THROWS_WITH(parse_pen_trace_csv(header + row + "\n", "a.csv", p),
                      Catch::Contains("a.csv:3") && Catch::Contains(named));
  }
  // Rows past a limit are refused at the first one over it, as the general way does.
  PenTraceCsvOptions options;
  options.max_samples = 1;
  CHECK_THROWS_WITH(parse_pen_trace_csv(header + "0.1,0,0,1\n", "a.csv", p, options),
                    Catch::Contains("a.csv:3") && Catch::Contains("more than 1 samples"));
  options = {};
  options.max_pen_down_segments = 1;
  CHECK_THROWS_WITH(parse_pen_trace_csv(header + "0.1,0,0,0\n0.2,0,0,1\n", "a.csv", p, options),
                    Catch::Contains("a.csv:4") && Catch::Contains("pen-down segments"));
  // Values exact where they stand in the row, a 16-digit one through the general way.
  const auto samples =
      parse_pen_trace_csv(header + "0.1,-0,1234567890.12345,0\n0.2,0.1234567890123456,5.,1\n", "a.csv", p);
  REQUIRE(samples.size() == 3);
  CHECK(std::signbit(samples[1].position_m.x()));
  CHECK(samples[1].position_m.y() == 1234567890.12345);
  CHECK_FALSE(samples[1].pen_down);
  CHECK(samples[2].position_m.x() == 0.1234567890123456);
  CHECK(samples[2].position_m.y() == 5.0);
}

namespace {

// Every row `for_each_pen_trace_row` gives of `file`, and of its bytes read whole.
std::vector<PenTraceRow> rows_of_file(const std::filesystem::path& file, const PenTraceCsvOptions& options) {
  std::vector<PenTraceRow> rows;
  for_each_pen_trace_row(file, Placement{}, options, [&rows](const PenTraceRow& r) { rows.push_back(r); });
  return rows;
}

std::vector<PenTraceRow> rows_of_bytes(const std::string& bytes, const PenTraceCsvOptions& options) {
  std::vector<PenTraceRow> rows;
  for_each_pen_trace_row_of_bytes(bytes, "the trace", Placement{}, options,
                                  [&rows](const PenTraceRow& r) { rows.push_back(r); });
  return rows;
}

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("A trace's bytes read whole give the rows its file gives, in each of its formats",
          "[pen_trace_csv]") {
  std::vector<TrialSample> trace(3000);
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const double t = 0.001 * static_cast<double>(i);
    trace[i].time_s = t;
    trace[i].position_m = Vec3(0.01 * std::sin(t), 0.01 * std::cos(3 * t), i % 700 < 500 ? 0.0 : 0.004);
    trace[i].force_n = Vec3(0.2 * std::cos(t), -0.1, 1.0);
  }
  PenTraceCsvOptions options;
  options.read_force = true;
  const std::string csv = trial_csv(trace);
  const TemporaryFile plain(csv);
  const TemporaryFile hdf5(trial_trace_hdf5(trace), "trace.trace.h5");
  const TemporaryFile gzip("", "trace.csv.gz");
  write_gzip(gzip.path, csv);
  // Two gzip members one after the other (as `cat a.gz b.gz` makes): one text, as gunzip reads it.
  const TemporaryFile members("", "members.csv.gz");
  write_gzip(members.path, csv.substr(0, csv.size() / 2));
  const std::size_t second_member = file_bytes(members.path).size();  // where the second member starts
  {
    const TemporaryFile second("", "second.gz");
    write_gzip(second.path, csv.substr(csv.size() / 2));
    std::ofstream(members.path, std::ios::binary | std::ios::app) << file_bytes(second.path);
  }
  const std::vector<PenTraceRow> expected = rows_of_file(plain.path, options);
  REQUIRE(expected.size() == trace.size());
  std::size_t lifted = 0;
  for (const std::filesystem::path& file : {plain.path, hdf5.path, gzip.path, members.path}) {
    INFO(file.filename().string());
    const std::vector<PenTraceRow> from_file = rows_of_file(file, options);
    const std::vector<PenTraceRow> from_bytes = rows_of_bytes(file_bytes(file), options);
    REQUIRE(from_file.size() == expected.size());
    REQUIRE(from_bytes.size() == expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      CHECK(from_bytes[i].sample.time_s == from_file[i].sample.time_s);
      CHECK(from_bytes[i].sample.position_m == from_file[i].sample.position_m);
      CHECK(from_bytes[i].sample.pen_down == from_file[i].sample.pen_down);
      CHECK(from_bytes[i].in_plane_force_n == from_file[i].in_plane_force_n);
      CHECK(from_file[i].sample.time_s ==
            Approx(expected[i].sample.time_s).margin(1e-9));  // the formats agree
      lifted += from_bytes[i].sample.pen_down ? 0 : 1;
    }
  }
  CHECK(lifted > 0);  // both pen states were read
  // Damage is named by the source given: a cut gzip stream, a cut HDF5 trace, a text over the limit.
  const std::string compressed = file_bytes(gzip.path);
  CHECK_THROWS_WITH(rows_of_bytes(compressed.substr(0, compressed.size() / 2), options),
                    Catch::Contains("the trace") && Catch::Contains("gzip"));
  const std::string h5 = file_bytes(hdf5.path);
  CHECK_THROWS_WITH(rows_of_bytes(h5.substr(0, h5.size() - 100), options), Catch::Contains("the trace"));
  // Bytes after the last member that start no other (a chunk whose header is damaged, plain text appended,
  // padding) would be left out without a word: refused from a file and from bytes alike, naming where.
  const std::string two = file_bytes(members.path);
  REQUIRE(two.substr(second_member, 2) == "\x1f\x8b");
  std::string flipped = two;
  flipped[second_member] = '\x1e';
  for (const std::string& damaged :
       {flipped, compressed + "0.5,0,0,1\n", compressed + std::string(512, '\0'), compressed + "\x1f"}) {
    const std::size_t at = damaged == flipped ? second_member : compressed.size();
    const std::string where = "at byte " + std::to_string(at) + ", after its last member";
    CHECK_THROWS_WITH(rows_of_bytes(damaged, options),
                      Catch::Contains("the trace") && Catch::Contains(where));
    const TemporaryFile file(damaged, "damaged.csv.gz");
    CHECK_THROWS_WITH(rows_of_file(file.path, options),
                      Catch::Contains("damaged.csv.gz") && Catch::Contains(where) &&
                          Catch::Contains(std::to_string(damaged.size() - at) + " bytes"));
  }
  PenTraceCsvOptions small = options;
  small.max_file_bytes = compressed.size() + 1;  // the gzip file is under it, its text is not
  REQUIRE(csv.size() > small.max_file_bytes);
  CHECK_THROWS_WITH(rows_of_bytes(compressed, small),
                    Catch::Contains("the trace") && Catch::Contains("the limit"));
  small.max_file_bytes = h5.size() - 1;
  CHECK_THROWS_WITH(rows_of_bytes(h5, small),
                    Catch::Contains("the trace") && Catch::Contains("over the limit"));
}
