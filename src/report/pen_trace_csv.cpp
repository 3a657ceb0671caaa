#include "calligraphy/report/pen_trace_csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <utility>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/report/trace_columns.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "report/compressed_text.hpp"

namespace calligraphy {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

// A field as RFC 4180 allows it to be written, in double quotes ("t", "0.001", as spreadsheet programs write
// every field): the text between them, when they enclose it and it holds no quote of its own. Any other
// field is as it is (a quote left in a number or a name is then refused as such).
std::string_view unquoted(std::string_view s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"' && s.substr(1, s.size() - 2).find('"') == s.npos)
    return trimmed(s.substr(1, s.size() - 2));
  return s;
}

// The first `wanted` fields of `line`, trimmed and unquoted, into `fields` (kept between lines, so that a
// line allocates nothing); returns how many fields the line has in all, the rest counted rather than split: a
// trace has millions of lines and a reader needs a few of its columns.
std::size_t split_fields(std::string_view line, std::size_t wanted, std::vector<std::string_view>& fields) {
  fields.clear();
  const char* start = line.data();
  const char* const end = start + line.size();
  for (const char* at = start;; ++at) {
    if (at != end && *at != ',') continue;
    fields.push_back(unquoted(trimmed(std::string_view(start, static_cast<std::size_t>(at - start)))));
    if (at == end) return fields.size();
    start = at + 1;
    if (fields.size() == wanted) return wanted + 1 + static_cast<std::size_t>(std::count(start, end, ','));
  }
}

// Where the columns are (0-based field numbers).
struct Columns {
  std::size_t count = 0;
  std::size_t t = 0, x = 0, y = 0;
  std::optional<std::size_t> pen;
  std::optional<std::size_t> z;
  std::size_t fx = 0, fy = 0;  // with PenTraceCsvOptions::read_force
  std::size_t used = 0;        // the fields a row is read up to (one past the last column read)
  // What each of those fields is, for the fast path (Reader::plain_row)
  enum class Role : unsigned char { skip, t, x, y, pen, z, fx, fy };
  std::vector<Role> roles;
};

class Reader {
 public:
  Reader(const std::string& source, const Placement& placement, const PenTraceCsvOptions& options,
         const std::function<void(const PenTraceRow&)>& sink)
      : source_(source), placement_(placement), options_(options), sink_(sink) {}

  /// One line of the text, without its LF.
  void line(std::string_view line) {
    ++line_number_;
    // A UTF-8 byte-order mark, as spreadsheet programs write at the start of a CSV file.
    constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
    if (line_number_ == 1 && line.starts_with(kByteOrderMark)) line.remove_prefix(kByteOrderMark.size());
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (columns_ && plain_row(line)) return;
    if (trimmed(line).empty() || trimmed(line).front() == '#') return;
    const std::size_t count = split_fields(line, columns_ ? columns_->used : fields_.max_size(), fields_);
    const std::vector<std::string_view>& fields = fields_;
    if (!columns_) {
      // Text of other programs that would be refused for a column it seems to lack or to name twice: Excel's
      // "Unicode text" (UTF-16) and lines ending in CR alone (classic Mac OS's "CSV (Macintosh)").
      if (line_number_ == 1 && (line.starts_with("\xFF\xFE") || line.starts_with("\xFE\xFF")))
        fail("UTF-16 text (its byte-order mark): a trace is UTF-8 text, save it as UTF-8 CSV");
      // Another file of the program given in a trace's place (a trial's --json record, a protocol): say what
      // it is, not that it lacks a column.
      if (line_number_ == 1) {
        std::string_view start = line.starts_with("\xEF\xBB\xBF") ? line.substr(3) : line;
        start.remove_prefix(std::min(start.find_first_not_of(" \t"), start.size()));
        if (start.starts_with('{') || start.starts_with('['))
          fail(
              "a JSON document, not a trace (a trial's trace is its --csv file, or `calligraphy trace` of a "
              "session's .trace.h5)");
        if (start.starts_with('<')) fail("markup (an SVG drawing, an HTML page or XML), not a trace");
      }
      if (line.find('\r') != std::string_view::npos)
        fail(
            "a carriage return within the header line: lines ending in CR alone are not read (end them in LF "
            "or CR LF)");
      header_.assign(fields.begin(), fields.end());
      columns_ = header(fields);
      return;
    }
    if (samples_ == options_.max_samples) {
      fail("more than " + std::to_string(options_.max_samples) +
           " samples, the limit of one trace (the rest of the file is not read)");
    }
    const PenTraceRow current = row(fields, count, *columns_);
    if (current.sample.pen_down && (samples_ == 0 || !previous_.pen_down) &&
        ++pen_down_segments_ > options_.max_pen_down_segments) {
      fail("more than " + std::to_string(options_.max_pen_down_segments) +
           " pen-down segments, the limit of one scored trace (the rest of the file is not read)");
    }
    if (samples_ > 0 && current.sample.time_s < previous_.time_s) {
      fail(columns_->t, fields[columns_->t],
           "time goes backwards (previous sample at " + shortest_decimal(previous_.time_s) + " s)");
    }
    ++samples_;
    previous_ = current.sample;
    sink_(current);
  }

  // A row as a trial's trace has millions of: no blank, comment or padding, every value read a plain decimal
  // (parse_plain_decimal) where it stands, in one pass over the line without splitting it into fields, and
  // taken when it passes every check. Returns false, having changed nothing, for anything else (another
  // number format, a bad value, a limit reached): the general path reads that line, to the same values, or
  // fails naming its line and column.
  bool plain_row(std::string_view line) {
    const Columns& c = *columns_;
    const char* at = line.data();
    const char* const end = at + line.size();
    if (at == end || *at == '#' || is_blank(*at)) return false;
    double values[8] = {};  // by Columns::Role
    bool pen = false;
    for (std::size_t i = 0; i < c.used; ++i) {
      if (i > 0) {
        if (at == end || *at != ',') return false;
        ++at;
      }
      const Columns::Role role = c.roles[i];
      if (role == Columns::Role::skip) {
        const void* comma = std::memchr(at, ',', static_cast<std::size_t>(end - at));
        at = comma == nullptr ? end : static_cast<const char*>(comma);
      } else if (role == Columns::Role::pen) {
        if (at == end || (*at != '0' && *at != '1')) return false;
        pen = *at++ == '1';
      } else {
        at = parse_plain_decimal(at, end, values[static_cast<std::size_t>(role)]);
        if (at == nullptr) return false;
      }
    }
    if (at != end && *at != ',') return false;
    if (c.used + static_cast<std::size_t>(std::count(at, end, ',')) != c.count) return false;
    PenTraceRow r;
    PenSample& s = r.sample;
    s.time_s = values[static_cast<std::size_t>(Columns::Role::t)];
    const Vec2 xy(values[static_cast<std::size_t>(Columns::Role::x)],
                  values[static_cast<std::size_t>(Columns::Role::y)]);
    s.position_m = options_.units == TraceUnits::data ? placement_.to_paper(xy) : xy;
    if (!s.position_m.allFinite()) return false;
    s.pen_down = c.pen ? pen
                       : values[static_cast<std::size_t>(Columns::Role::z)] - options_.paper_z_m <=
                             options_.contact_threshold_m;
    if (options_.read_force) {
      r.in_plane_force_n = Vec2(values[static_cast<std::size_t>(Columns::Role::fx)],
                                values[static_cast<std::size_t>(Columns::Role::fy)])
                               .norm();
    }
    const bool starts_segment = s.pen_down && (samples_ == 0 || !previous_.pen_down);
    if (samples_ == options_.max_samples ||
        (starts_segment && pen_down_segments_ == options_.max_pen_down_segments) ||
        (samples_ > 0 && s.time_s < previous_.time_s)) {
      return false;
    }
    pen_down_segments_ += starts_segment ? 1 : 0;
    ++samples_;
    previous_ = s;
    sink_(r);
    return true;
  }

  /// The lines of `text` that end in LF; returns where the unfinished last line starts (text.size() when
  /// none). Reports progress as `offset` + the bytes passed of `total`.
  std::size_t lines(std::string_view text, std::size_t offset, std::size_t total) {
    std::size_t line_start = 0;
    while (true) {
      const std::size_t newline = text.find('\n', line_start);
      if (newline == std::string_view::npos) return line_start;
      if (options_.progress && line_number_ % kProgressLines == 0)
        options_.progress(std::min(offset + line_start, total), total);
      line(text.substr(line_start, newline - line_start));
      line_start = newline + 1;
    }
  }

  void finish(std::size_t total) {
    if (!columns_) throw DataError(source_ + ": no header line (expected columns t, x, y and pen or z)");
    if (options_.progress) options_.progress(total, total);
  }

  void parse(std::string_view text) {
    const std::size_t rest = lines(text, 0, text.size());
    if (rest < text.size()) line(text.substr(rest));
    finish(text.size());
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw DataError(source_ + ":" + std::to_string(line_number_) + ": " + what);
  }
  [[noreturn]] void fail(std::size_t column, std::string_view value, const std::string& what) const {
    // The field as printable text: a NUL byte would otherwise end the message where what() is read as a C
    // string, and a control character would act on the terminal.
    std::string message = "column " + std::to_string(column + 1);
    message.append(" (").append(printable_one_line(header_[column], 200)).append("), value '");
    message.append(printable_one_line(value, 200)).append("': ").append(what);
    fail(message);
  }

  Columns header(const std::vector<std::string_view>& names) {
    Columns c;
    c.count = names.size();
    std::optional<std::size_t> t, x, y, fx, fy;
    // A trace column by its name in the table or its file name ("t_s" or "t": trace_columns.hpp).
    const auto file_name = [](std::string_view name) {
      const std::optional<TraceColumnInfo> info = trace_column(name);
      return info ? info->file_name : name;
    };
    // The names seen, by their file name: a header may have a hundred thousand columns.
    std::unordered_set<std::string_view> seen;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const std::string_view name = file_name(names[i]);
      if (!names[i].empty() && !seen.insert(name).second)
        fail("column name '" + printable_one_line(names[i], 200) + "' appears twice");
      if (name == "t") t = i;
      if (name == "x") x = i;
      if (name == "y") y = i;
      if (name == "pen") c.pen = i;
      if (name == "z") c.z = i;
      if (name == "fx") fx = i;
      if (name == "fy") fy = i;
    }
    for (const auto& [column, name] : {std::pair{t, "t"}, std::pair{x, "x"}, std::pair{y, "y"}}) {
      if (!column) fail(std::string("header has no column '") + name + "' (expected t, x, y and pen or z)");
    }
    if (options_.read_force) {
      for (const auto& [column, name] : {std::pair{fx, "fx"}, std::pair{fy, "fy"}}) {
        if (!column) fail(std::string("header has no column '") + name + "' (a trial's trace has fx and fy)");
      }
      c.fx = *fx;
      c.fy = *fy;
    }
    if (!c.pen && !c.z) fail("header has neither a 'pen' nor a 'z' column");
    if (c.pen && c.z)
      fail("header has both 'pen' and 'z' columns; give one, so that pen contact is unambiguous");
    c.t = *t;
    c.x = *x;
    c.y = *y;
    c.used = 1 + std::max({c.t, c.x, c.y, c.pen.value_or(0), c.z.value_or(0), c.fx, c.fy});
    c.roles.assign(c.used, Columns::Role::skip);
    c.roles[c.t] = Columns::Role::t;
    c.roles[c.x] = Columns::Role::x;
    c.roles[c.y] = Columns::Role::y;
    if (c.pen) c.roles[*c.pen] = Columns::Role::pen;
    if (c.z) c.roles[*c.z] = Columns::Role::z;
    if (options_.read_force) {
      c.roles[c.fx] = Columns::Role::fx;
      c.roles[c.fy] = Columns::Role::fy;
    }
    return c;
  }

  // A leading '+', as C's printf("%+f") writes a number, before the number it signs (never before a sign).
  static std::string_view unsigned_part(std::string_view field) {
    if (field.size() > 1 && field.front() == '+' && field[1] != '+' && field[1] != '-')
      field.remove_prefix(1);
    return field;
  }

  double number(const std::vector<std::string_view>& fields, std::size_t column) const {
    const std::string_view field = unsigned_part(fields[column]);
    // A plain decimal (a trial's trace has millions) read where it stands, to the same value as
    // parse_finite_double gives but without the round trip through its optional, which costs as much again.
    double plain = 0.0;
    const char* const end = field.data() + field.size();
    if (!field.empty() && parse_plain_decimal(field.data(), end, plain) == end) return plain;
    const std::optional<double> value = parse_finite_double(field);
    if (!value)
      fail(column, fields[column],
           "not a number (a finite decimal within the range of a double is expected)");
    return *value;
  }

  // `fields`: the row's first c.used fields; `count`: its fields in all.
  PenTraceRow row(const std::vector<std::string_view>& fields, std::size_t count, const Columns& c) const {
    if (count != c.count) fail(std::to_string(count) + " fields, the header has " + std::to_string(c.count));
    PenTraceRow r;
    PenSample& s = r.sample;
    s.time_s = number(fields, c.t);
    const Vec2 xy(number(fields, c.x), number(fields, c.y));
    s.position_m = options_.units == TraceUnits::data ? placement_.to_paper(xy) : xy;
    if (!s.position_m.allFinite()) fail(c.x, fields[c.x], "not finite once converted to metres");
    // Scoring measures every sample in the character's data units too: a position too far away to be one
    // there (1e308 m) is refused here, at its line, rather than by the scorer without the file's name.
    if (const Vec2 data = placement_.to_data(s.position_m); !data.allFinite()) {
      const std::size_t far = std::isfinite(data.x()) ? c.y : c.x;
      fail(far, fields[far], "too far from the character to convert to its data units");
    }
    if (c.pen) {
      // The number 1 or 0 however a program spells it: numpy.savetxt writes 1.000000000000000000e+00 and
      // pandas a float column's 1.0, which Python's score takes from the same columns.
      const std::string_view pen = fields[*c.pen];
      const std::optional<double> value = pen == "1"   ? 1.0
                                          : pen == "0" ? 0.0
                                                       : parse_finite_double(unsigned_part(pen));
      if (!value || (*value != 0.0 && *value != 1.0)) fail(*c.pen, pen, "pen must be 1 (down) or 0 (up)");
      s.pen_down = *value == 1.0;
    } else {
      s.pen_down = number(fields, *c.z) - options_.paper_z_m <= options_.contact_threshold_m;
    }
    if (options_.read_force) r.in_plane_force_n = Vec2(number(fields, c.fx), number(fields, c.fy)).norm();
    return r;
  }

  const std::string& source_;
  const Placement& placement_;
  const PenTraceCsvOptions& options_;
  const std::function<void(const PenTraceRow&)>& sink_;
  static constexpr std::size_t kProgressLines = std::size_t{1} << 16;
  std::size_t line_number_ = 0;
  std::vector<std::string> header_;
  std::optional<Columns> columns_;
  std::vector<std::string_view> fields_;
  std::size_t samples_ = 0;  // given to the sink
  PenSample previous_;       // the last of them
  std::size_t pen_down_segments_ = 0;
};

// The LFs of `text`, plus one: counted 255 bytes at a time into a byte, which the compiler makes a compare
// and subtract of 16 or 32 bytes at once (std::count widens every byte's count to 64 bits, 8 times slower).
std::size_t count_lines(std::string_view text) {
  std::size_t lines = 1;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t stop = std::min(text.size(), i + 255);
    unsigned char block = 0;
    for (; i < stop; ++i) block = static_cast<unsigned char>(block + (text[i] == '\n' ? 1 : 0));
    lines += block;
  }
  return lines;
}

// An unfinished line that is a comment ('#' after blanks) cut after its '#': the reader skips the line
// whatever follows, so a comment of any length holds no more memory than that.
void keep_comment_mark(std::string& unfinished) {
  const std::size_t at = unfinished.find_first_not_of(" \t");
  if (at != std::string::npos && unfinished[at] == '#' && unfinished.size() > at + 1)
    unfinished.resize(at + 1);
}

void check_options(const PenTraceCsvOptions& options, const Placement& placement) {
  if (!std::isfinite(options.contact_threshold_m)) {
    throw InvalidArgument("PenTraceCsvOptions: contact threshold " +
                          shortest_decimal(options.contact_threshold_m) + " m is not finite");
  }
  if (!std::isfinite(options.paper_z_m)) {
    throw InvalidArgument("PenTraceCsvOptions: paper height " + shortest_decimal(options.paper_z_m) +
                          " m is not finite");
  }
  if (options.max_file_bytes == 0) throw InvalidArgument("PenTraceCsvOptions: max_file_bytes is 0");
  if (options.max_samples == 0) throw InvalidArgument("PenTraceCsvOptions: max_samples is 0");
  if (options.max_pen_down_segments == 0) {
    throw InvalidArgument("PenTraceCsvOptions: max_pen_down_segments is 0");
  }
  if (options.units == TraceUnits::data &&
      (!placement.origin_m.allFinite() || !std::isfinite(placement.metres_per_unit) ||
       !(placement.metres_per_unit > 0.0))) {
    throw InvalidArgument("parse_pen_trace_csv: the placement (" +
                          shortest_decimal(placement.metres_per_unit) +
                          " m per unit) cannot convert data units to metres");
  }
}

// True when `file` starts as a trace saved in HDF5 (trace_hdf5.hpp) rather than CSV text.
bool is_trace_hdf5_file(const std::filesystem::path& file) {
  // Only a regular file is opened: a FIFO or a device would block or never end (the CSV reader refuses them).
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return false;
  std::ifstream in(file, std::ios::binary);
  char head[32] = {};
  in.read(head, sizeof head);
  return is_trace_hdf5(std::string_view(head, static_cast<std::size_t>(in.gcount())));
}

// The rows of an HDF5 trace's columns with the CSV reader's checks and limits; errors name the sample
// (1-based) of `source`.
void for_each_trace_hdf5_row(const TraceColumns& c, const std::string& source, const Placement& placement,
                             const PenTraceCsvOptions& options,
                             const std::function<void(const PenTraceRow&)>& row) {
  const auto fail = [&source](std::size_t i, const std::string& what) {
    throw DataError(source + ": sample " + std::to_string(i + 1) + ": " + what);
  };
  if (c.size() > options.max_samples) {
    fail(options.max_samples,
         "more than " + std::to_string(options.max_samples) + " samples, the limit of one trace");
  }
  std::size_t segments = 0;
  PenTraceRow r;
  PenSample& s = r.sample;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const bool was_down = s.pen_down;
    if (i > 0 && c.time_s[i] < s.time_s)
      fail(i, "time goes backwards (previous sample at " + shortest_decimal(s.time_s) + " s)");
    s.time_s = c.time_s[i];
    const Vec2 xy(c.x_m[i], c.y_m[i]);
    s.position_m = options.units == TraceUnits::data ? placement.to_paper(xy) : xy;
    if (!s.position_m.allFinite()) fail(i, "position not finite once converted to metres");
    if (!placement.to_data(s.position_m).allFinite()) {
      fail(i, "position too far from the character to convert to its data units");
    }
    s.pen_down = c.z_m[i] - options.paper_z_m <= options.contact_threshold_m;
    if (s.pen_down && (i == 0 || !was_down) && ++segments > options.max_pen_down_segments) {
      fail(i, "more than " + std::to_string(options.max_pen_down_segments) +
                  " pen-down segments, the limit of one scored trace");
    }
    if (options.read_force) {
      if (!std::isfinite(c.fx_n[i]) || !std::isfinite(c.fy_n[i])) fail(i, "force not finite");
      r.in_plane_force_n = Vec2(c.fx_n[i], c.fy_n[i]).norm();
    }
    row(r);
  }
  if (options.progress) options.progress(c.size(), c.size());
}

}  // namespace

TraceUnits parse_trace_units(std::string_view name) {
  if (name == "metres") return TraceUnits::metres;
  if (name == "data") return TraceUnits::data;
  throw InvalidArgument("trace units '" + std::string(name) + "' are neither 'metres' nor 'data'");
}

std::vector<PenSample> parse_pen_trace_csv(std::string_view text, const std::string& source,
                                           const Placement& placement, const PenTraceCsvOptions& options) {
  check_options(options, placement);
  std::vector<PenSample> samples;
  // A sample a line at most: counting them first costs less than growing the vector of a long trace.
  samples.reserve(std::min(count_lines(text), options.max_samples));
  const std::function<void(const PenTraceRow&)> keep = [&samples](const PenTraceRow& r) {
    samples.push_back(r.sample);
  };
  Reader(source, placement, options, keep).parse(text);
  return samples;
}

void for_each_pen_trace_row(const std::filesystem::path& file, const Placement& placement,
                            const PenTraceCsvOptions& options,
                            const std::function<void(const PenTraceRow&)>& row) {
  check_options(options, placement);
  if (is_trace_hdf5_file(file)) {
    const TraceColumns columns = read_trace_hdf5(file, options.max_file_bytes, TraceColumnSet::pen);
    for_each_trace_hdf5_row(columns, file.string(), placement, options, row);
    return;
  }
  // Streamed a block at a time (decompressed on the way for a gzip file), so that memory holds a block, not
  // the file: a trace over a limit is refused at its line without the rest being read.
  const std::string name = file.string();
  TextFileReader in(file, options.max_file_bytes, options.max_file_bytes);
  const auto size = static_cast<std::size_t>(in.file_bytes());
  Reader reader(name, placement, options, row);
  constexpr std::size_t kBlockBytes = std::size_t{1} << 20;
  std::string buffer;  // an unfinished line, then the next block
  while (true) {
    const std::size_t kept = buffer.size();
    const auto offset = static_cast<std::size_t>(in.file_offset());  // on disk, for the progress
    buffer.resize(kept + kBlockBytes);
    const std::size_t got = in.read(buffer.data() + kept, kBlockBytes);
    buffer.resize(kept + got);
    if (got == 0) break;
    // A block that ends no line adds to the unfinished one, which is not scanned again (a long line would
    // be scanned at every block, in time growing with its square).
    if (std::memchr(buffer.data() + kept, '\n', got) != nullptr)
      buffer.erase(0, reader.lines(buffer, offset, size));
    keep_comment_mark(buffer);
  }
  if (!buffer.empty()) reader.line(buffer);
  reader.finish(size);
}

void for_each_pen_trace_row_of_bytes(std::string_view bytes, const std::string& source,
                                     const Placement& placement, const PenTraceCsvOptions& options,
                                     const std::function<void(const PenTraceRow&)>& row) {
  check_options(options, placement);
  if (bytes.size() > options.max_file_bytes) {
    throw DataError(source + ": " + std::to_string(bytes.size()) + " bytes, over the limit of " +
                    std::to_string(options.max_file_bytes));
  }
  if (is_trace_hdf5(bytes.substr(0, 32))) {
    const TraceColumns columns = parse_trace_hdf5(bytes, source, TraceColumnSet::pen);
    for_each_trace_hdf5_row(columns, source, placement, options, row);
    return;
  }
  const std::string text = gunzip_text(bytes, source, options.max_file_bytes);
  Reader(source, placement, options, row).parse(text);
}

std::vector<PenSample> read_pen_trace_csv(const std::filesystem::path& file, const Placement& placement,
                                          const PenTraceCsvOptions& options) {
  std::vector<PenSample> samples;
  for_each_pen_trace_row(file, placement, options,
                         [&samples](const PenTraceRow& r) { samples.push_back(r.sample); });
  return samples;
}

}  // namespace calligraphy
