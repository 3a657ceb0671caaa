#include "calligraphy/report/trace_hdf5.hpp"

#include <hdf5.h>
#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <system_error>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/report/trace_columns.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "core/whole_file.hpp"

namespace calligraphy {
namespace {

constexpr std::string_view kMagic = "calligraphy-trace\n";
// The root's `format` attribute: the user block's first line, for readers of the HDF5 alone.
constexpr std::string_view kFormat = kMagic.substr(0, kMagic.size() - 1);
constexpr int kVersion = 1;
// HDF5 looks for its superblock at 0, 512, 1024, ...: the smallest user block is 512 bytes.
constexpr std::size_t kUserBlockBytes = 512;
constexpr hsize_t kChunkSamples = hsize_t{1} << 16;
constexpr int kDeflateLevel = 6;

// One HDF5 identifier, closed with its own close function when it goes.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  [[nodiscard]] hid_t get() const noexcept { return id_; }
  [[nodiscard]] bool ok() const noexcept { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// HDF5 prints its error stack to stderr unless told not to, per thread in a thread-safe build: errors here
// become exceptions that name the file instead.
void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

// The core driver keeps files in memory; HDF5 refuses a second open file of the same name, so each gets its
// own. Opening an image, HDF5 also refuses a name that exists on disk: under /dev/null (a file) none can.
std::string image_name() {
  static std::atomic<unsigned long long> counter{0};
  return "/dev/null/calligraphy-trace-image-" + std::to_string(counter.fetch_add(1));
}

// `increment_bytes`: the core driver's allocation step, which it also zeroes; a read never grows the image.
Handle memory_file_access(std::size_t increment_bytes) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.ok() || H5Pset_fapl_core(fapl.get(), increment_bytes, /*backing_store=*/0) < 0)
    throw DataError("trace file: HDF5 cannot make an in-memory file (out of memory?)");
  return fapl;
}

// ---- writing ----

void write_string_attribute(hid_t object, const char* name, std::string_view value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!type.ok() || !space.ok() || H5Tset_size(type.get(), value.size()) < 0)
    throw DataError(std::string("trace file: HDF5 cannot make attribute ") + name);
  Handle attribute(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attribute.ok() || H5Awrite(attribute.get(), type.get(), value.data()) < 0)
    throw DataError(std::string("trace file: HDF5 cannot write attribute ") + name);
}

template <typename T>
void write_number_attribute(hid_t object, const char* name, hid_t file_type, hid_t memory_type, T value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attribute.ok() || H5Awrite(attribute.get(), memory_type, &value) < 0)
    throw DataError(std::string("trace file: HDF5 cannot write attribute ") + name);
}

hid_t write_column(hid_t file, const char* name, hid_t file_type, hid_t memory_type, const void* data,
                   std::size_t count) {
  const hsize_t dims[1] = {count};
  const hsize_t chunk[1] = {std::max<hsize_t>(1, std::min<hsize_t>(count, kChunkSamples))};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose);
  Handle create(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  // No creation time in the object's header: the same trace gives the same bytes.
  if (!space.ok() || !create.ok() || H5Pset_chunk(create.get(), 1, chunk) < 0 ||
      H5Pset_shuffle(create.get()) < 0 || H5Pset_deflate(create.get(), kDeflateLevel) < 0 ||
      H5Pset_obj_track_times(create.get(), 0) < 0)
    throw DataError(std::string("trace file: HDF5 cannot lay out column ") + name);
  const hid_t dataset =
      H5Dcreate2(file, name, file_type, space.get(), H5P_DEFAULT, create.get(), H5P_DEFAULT);
  if (dataset < 0) throw DataError(std::string("trace file: HDF5 cannot make column ") + name);
  if (count > 0 && H5Dwrite(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    H5Dclose(dataset);
    throw DataError(std::string("trace file: HDF5 cannot write column ") + name);
  }
  return dataset;
}

// `value` to `decimals` decimals as the CSV writes it (std::to_chars, fixed), as the integer of its digits:
// the column then reads back, as integer / 10^decimals, to the double the CSV's text parses to.
bool scaled_integer(double value, int decimals, std::int64_t& out) {
  if (!std::isfinite(value) || !(std::abs(value) < 1e15)) return false;
  char text[64];
  const auto [end, error] =
      std::to_chars(text, text + sizeof text, value, std::chars_format::fixed, decimals);
  if (error != std::errc{}) return false;
  std::int64_t digits = 0;
  bool negative = false;
  for (const char* at = text; at != end; ++at) {
    if (*at == '-')
      negative = true;
    else if (*at != '.')
      digits = digits * 10 + (*at - '0');
  }
  if (digits >= (std::int64_t{1} << 53)) return false;  // beyond an exact double
  out = negative ? -digits : digits;
  return true;
}

// The unit of the measured column the trace files name `file_name` ("t", "x", "fx"), from the one table of
// a trace's columns (trace_columns.hpp): what its `unit` attribute says.
std::string unit_of(const char* file_name) {
  const std::optional<TraceColumnInfo> column = trace_column(file_name);
  return column ? std::string(column->unit) : std::string();
}

void write_scaled_column(hid_t file, const char* name, int decimals, const std::vector<TrialSample>& trace,
                         double (*get)(const TrialSample&)) {
  std::vector<std::int64_t> integers(trace.size());
  bool exact = true;
  bool fits_32 = true;
  for (std::size_t i = 0; i < trace.size() && exact; ++i) {
    exact = scaled_integer(get(trace[i]), decimals, integers[i]);
    fits_32 = fits_32 && integers[i] >= std::numeric_limits<std::int32_t>::min() &&
              integers[i] <= std::numeric_limits<std::int32_t>::max();
  }
  hid_t dataset = -1;
  if (!exact) {  // a value no integer holds: the column as doubles, exactly as recorded
    std::vector<double> values(trace.size());
    for (std::size_t i = 0; i < trace.size(); ++i) values[i] = get(trace[i]);
    dataset = write_column(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), values.size());
  } else if (fits_32) {
    std::vector<std::int32_t> narrow(integers.begin(), integers.end());
    dataset = write_column(file, name, H5T_STD_I32LE, H5T_NATIVE_INT32, narrow.data(), narrow.size());
  } else {
    dataset = write_column(file, name, H5T_STD_I64LE, H5T_NATIVE_INT64, integers.data(), integers.size());
  }
  Handle closer(dataset, H5Dclose);
  write_string_attribute(dataset, "unit", unit_of(name));
  if (exact) write_number_attribute(dataset, "decimals", H5T_STD_I32LE, H5T_NATIVE_INT, decimals);
}

Handle state_type(hid_t base) {
  Handle type(H5Tenum_create(base), H5Tclose);
  for (std::uint8_t value = 0; value < 4; ++value) {
    if (!type.ok() || H5Tenum_insert(type.get(), to_string(static_cast<InteractionState>(value)), &value) < 0)
      throw DataError("trace file: HDF5 cannot make the state type");
  }
  return type;
}

// CRC-32 (ISO 3309, the polynomial of zlib and gzip) of `bytes`, by libdeflate: several times zlib's speed,
// and every trace read is checked whole.
unsigned long crc32_of(std::string_view bytes) { return libdeflate_crc32(0, bytes.data(), bytes.size()); }

// The user block: what the file is, its version, the length and CRC-32 of the HDF5 file after it, then zeros.
std::string user_block(int version, std::size_t length, unsigned long crc) {
  char text[kUserBlockBytes] = {};
  std::snprintf(text, sizeof text, "%.*sversion %d\nbytes %zu\ncrc32 %08lx\n",
                static_cast<int>(kMagic.size()), kMagic.data(), version, length, crc);
  return {text, sizeof text};
}

}  // namespace

std::string trial_trace_hdf5(const std::vector<TrialSample>& trace) {
  if (trace.size() > kMaxTraceSamples) {
    throw InvalidArgument("trial_trace_hdf5: " + std::to_string(trace.size()) +
                          " samples, more than a trace file holds (" + std::to_string(kMaxTraceSamples) +
                          ")");
  }
  silence_hdf5();
  Handle access = memory_file_access(std::size_t{1} << 20);
  Handle create(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  if (!create.ok() || H5Pset_userblock(create.get(), kUserBlockBytes) < 0 ||
      H5Pset_obj_track_times(create.get(), 0) < 0)
    throw DataError("trace file: HDF5 cannot set up a file");
  Handle file(H5Fcreate(image_name().c_str(), H5F_ACC_TRUNC, create.get(), access.get()), H5Fclose);
  if (!file.ok()) throw DataError("trace file: HDF5 cannot make an in-memory file");
  const hid_t root = file.get();
  write_string_attribute(root, "format", kFormat);
  write_number_attribute(root, "version", H5T_STD_I32LE, H5T_NATIVE_INT, kVersion);
  write_number_attribute(root, "samples", H5T_STD_U64LE, H5T_NATIVE_UINT64, std::uint64_t{trace.size()});

  write_scaled_column(root, "t", kTraceTimeDecimals, trace, [](const TrialSample& s) { return s.time_s; });
  write_scaled_column(root, "x", kTracePositionDecimals, trace,
                      [](const TrialSample& s) { return s.position_m.x(); });
  write_scaled_column(root, "y", kTracePositionDecimals, trace,
                      [](const TrialSample& s) { return s.position_m.y(); });
  write_scaled_column(root, "z", kTracePositionDecimals, trace,
                      [](const TrialSample& s) { return s.position_m.z(); });
  write_scaled_column(root, "fx", kTraceForceDecimals, trace,
                      [](const TrialSample& s) { return s.force_n.x(); });
  write_scaled_column(root, "fy", kTraceForceDecimals, trace,
                      [](const TrialSample& s) { return s.force_n.y(); });
  write_scaled_column(root, "fz", kTraceForceDecimals, trace,
                      [](const TrialSample& s) { return s.force_n.z(); });

  const std::size_t n = trace.size();
  std::vector<std::uint8_t> states(n), rewritten(n);
  std::vector<std::uint32_t> strokes(n), elements(n);
  std::vector<std::int32_t> attempts(n);
  for (std::size_t i = 0; i < n; ++i) {
    const TrialSample& s = trace[i];
    if (s.stroke > std::numeric_limits<std::uint32_t>::max() ||
        s.element > std::numeric_limits<std::uint32_t>::max())
      throw InvalidArgument("trial_trace_hdf5: sample " + std::to_string(i) +
                            " has a stroke or element index beyond 2^32 - 1");
    states[i] = static_cast<std::uint8_t>(s.state);
    strokes[i] = static_cast<std::uint32_t>(s.stroke);
    elements[i] = static_cast<std::uint32_t>(s.element);
    attempts[i] = s.attempt;
    rewritten[i] = s.rewritten ? 1 : 0;
  }
  {
    Handle file_states = state_type(H5T_STD_U8LE);
    Handle memory_states = state_type(H5T_NATIVE_UINT8);
    Handle(write_column(root, "state", file_states.get(), memory_states.get(), states.data(), n), H5Dclose);
  }
  Handle(write_column(root, "stroke", H5T_STD_U32LE, H5T_NATIVE_UINT32, strokes.data(), n), H5Dclose);
  Handle(write_column(root, "element", H5T_STD_U32LE, H5T_NATIVE_UINT32, elements.data(), n), H5Dclose);
  Handle(write_column(root, "attempt", H5T_STD_I32LE, H5T_NATIVE_INT32, attempts.data(), n), H5Dclose);
  Handle(write_column(root, "rewritten", H5T_STD_U8LE, H5T_NATIVE_UINT8, rewritten.data(), n), H5Dclose);

  if (H5Fflush(root, H5F_SCOPE_GLOBAL) < 0) throw DataError("trace file: HDF5 cannot finish the file");
  const ssize_t size = H5Fget_file_image(root, nullptr, 0);
  if (size <= 0) throw DataError("trace file: HDF5 gave no file image");
  std::string image(static_cast<std::size_t>(size), '\0');
  if (H5Fget_file_image(root, image.data(), image.size()) != size)
    throw DataError("trace file: HDF5 cannot copy the file image");
  // HDF5's image starts at its superblock: the user block it left room for goes before it.
  return user_block(kVersion, image.size(), crc32_of(image)) + image;
}

bool is_trace_hdf5(std::string_view first_bytes) noexcept { return first_bytes.starts_with(kMagic); }

namespace {

// ---- reading ----

[[noreturn]] void refuse(const std::string& source, const std::string& what) {
  throw DataError(source + ": " + what);
}

// The user block's checks: what the file is, its version, then that it is byte for byte the block this
// library writes for the rest's length and CRC-32.
void check_user_block(std::string_view bytes, const std::string& source) {
  if (!is_trace_hdf5(bytes))
    refuse(source, "not a calligraphy trace file (it does not start 'calligraphy-trace')");
  if (bytes.size() < kUserBlockBytes)
    refuse(source, "cut short (" + std::to_string(bytes.size()) + " bytes)");
  const std::string head(bytes.data(), strnlen(bytes.data(), kUserBlockBytes));
  int version = 0;
  if (std::sscanf(head.c_str() + kMagic.size(), "version %d\n", &version) != 1)
    refuse(source, "damaged header (no version)");
  if (version != kVersion) {
    refuse(source, "trace file version " + std::to_string(version) + ", this library reads version " +
                       std::to_string(kVersion) + (version > kVersion ? " (a newer library wrote it)" : ""));
  }
  unsigned long long length = 0;
  unsigned long crc = 0;
  if (std::sscanf(head.c_str() + kMagic.size(), "version %*d\nbytes %llu\ncrc32 %lx\n", &length, &crc) != 2)
    refuse(source, "damaged header (no bytes and crc32)");
  // The block must be the one this library writes for the numbers read, before a length is reported: sscanf
  // reads "bytes -5" as 2^64 - 5 and a number past 2^64 as 2^64 - 1, numbers the file does not say.
  if (bytes.substr(0, kUserBlockBytes) != user_block(version, static_cast<std::size_t>(length), crc))
    refuse(source, "damaged header");
  const std::string_view rest = bytes.substr(kUserBlockBytes);
  if (rest.size() != length) {
    refuse(source, std::to_string(rest.size()) + " bytes after its header where it says " +
                       std::to_string(length) + (rest.size() < length ? " (cut short)" : " (bytes added)"));
  }
  if (crc32_of(rest) != crc) refuse(source, "damaged (its CRC-32 does not match its contents)");
}

// HDF5 calls this before it follows an external link (to a dataset in another file): refused, and noted, so
// that no file but the trace is ever opened (a path the link names may be a FIFO, which open(2) waits on).
herr_t refuse_external_link(const char* /*parent_file*/, const char* /*parent_group*/,
                            const char* /*child_file*/, const char* /*child_object*/,
                            unsigned* /*access_flags*/, hid_t /*access*/, void* refused) {
  *static_cast<bool*>(refused) = true;
  return -1;
}

// The dataset `name` of a trace file, opened so that its values come from the file's own bytes, which the
// header's CRC-32 and a record's SHA-256 cover: a column that is an external link (or a soft link reaching
// one), a virtual dataset (its values mapped from other files) or kept in HDF5's external storage (raw bytes
// in files named by the dataset) is refused naming it, before HDF5 opens anything else. A link inside the
// file (hard or soft) is the dataset it names, as every HDF5 reader reads it. Refuses a missing column.
Handle open_column(hid_t file, const char* name, const std::string& source) {
  const std::string column = std::string("column '") + name + "'";
  if (H5Lexists(file, name, H5P_DEFAULT) <= 0) refuse(source, "no " + column);
  H5L_info_t link{};
  if (H5Lget_info(file, name, &link, H5P_DEFAULT) < 0) refuse(source, "no " + column);
  bool external_link = link.type == H5L_TYPE_EXTERNAL;
  Handle access(H5Pcreate(H5P_DATASET_ACCESS), H5Pclose);
  if (!access.ok() || H5Pset_elink_cb(access.get(), refuse_external_link, &external_link) < 0)
    refuse(source, "HDF5 cannot open " + column + " (out of memory?)");
  Handle dataset(external_link ? H5I_INVALID_HID : H5Dopen2(file, name, access.get()), H5Dclose);
  if (external_link) {
    refuse(source, column + " is a link to a dataset in another file, outside the trace file (whose CRC-32 " +
                       "and SHA-256 do not cover it)");
  }
  if (!dataset.ok()) refuse(source, column + " is not a dataset");
  Handle create(H5Dget_create_plist(dataset.get()), H5Pclose);
  if (!create.ok()) refuse(source, column + " cannot be read (damaged)");
  if (H5Pget_layout(create.get()) == H5D_VIRTUAL) {
    refuse(source, column + " is a virtual dataset, its values mapped from outside the trace file (which " +
                       "its CRC-32 and SHA-256 do not cover)");
  }
  if (H5Pget_external_count(create.get()) != 0) {
    refuse(source, column + " keeps its values in HDF5 external storage, outside the trace file (which " +
                       "its CRC-32 and SHA-256 do not cover)");
  }
  // Samples never written read as the fill value, which HDF5 leaves undefined (the reader's buffer as it was)
  // when the dataset has none or is never to be filled: such a column holds no values to read.
  H5D_fill_time_t fill_time = H5D_FILL_TIME_IFSET;
  H5D_fill_value_t fill_value = H5D_FILL_VALUE_DEFAULT;
  H5D_space_status_t allocated = H5D_SPACE_STATUS_ERROR;
  if (H5Pget_fill_time(create.get(), &fill_time) < 0 ||
      H5Pfill_value_defined(create.get(), &fill_value) < 0 ||
      H5Dget_space_status(dataset.get(), &allocated) < 0)
    refuse(source, column + " cannot be read (damaged)");
  if ((fill_time == H5D_FILL_TIME_NEVER || fill_value == H5D_FILL_VALUE_UNDEFINED) &&
      allocated != H5D_SPACE_STATUS_ALLOCATED) {
    refuse(source, column + " has samples that were never written and that HDF5 does not fill (their " +
                       "values are undefined)");
  }
  // Another program's filters are read through HDF5's pipeline; one this HDF5 lacks is named by its number
  // (its name is the file's text), not reported as damage.
  const int filters = H5Pget_nfilters(create.get());
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0;
    std::size_t values = 0;
    unsigned int filter_info = 0;
    const H5Z_filter_t filter = H5Pget_filter2(create.get(), static_cast<unsigned>(i), &flags, &values,
                                               nullptr, 0, nullptr, &filter_info);
    if (filter < 0) refuse(source, column + " cannot be read (damaged)");
    if (H5Zfilter_avail(filter) <= 0) {
      refuse(source, column + " is stored through HDF5 filter " + std::to_string(filter) +
                         ", which this program's HDF5 does not have");
    }
  }
  return dataset;
}

// The length of the one-dimensional dataset `name`, at most 2^40 (a damaged size is refused, never
// allocated).
std::size_t dataset_length(hid_t file, const char* name, const std::string& source) {
  Handle dataset = open_column(file, name, source);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  hsize_t dims[1] = {0};
  if (!space.ok() || H5Sget_simple_extent_ndims(space.get()) != 1 ||
      H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 1 || dims[0] > (hsize_t{1} << 40))
    refuse(source, std::string("column '") + name + "' is not one-dimensional or has a bad length");
  return static_cast<std::size_t>(dims[0]);
}

// ---- attributes ----
//
// Read only after the user block's CRC-32 has matched (check_user_block), so that the header messages they
// are decoded from are the bytes a writer made, not accidental damage; each is opened, its dataspace and type
// checked (one value, of the class the writer gives it, of bounded size) before H5Aread, which then reads it
// with its own type into a buffer of that size: HDF5 converts nothing a file describes.

// How an attribute is named in messages: "attribute /version", "column 'x': attribute /x/unit".
std::string attribute_path(const char* column, const char* name) {
  std::string path;
  if (column != nullptr) path.append("column '").append(column).append("': ");
  path.append("attribute /");
  if (column != nullptr) path.append(column).append("/");
  return path.append(name);
}

// The open attribute `name` of `object`, one value (a scalar dataspace) of class `expected` and at most
// `max_bytes` bytes; `bytes` is set to its size. Refuses naming the attribute when it is missing or other.
Handle open_attribute(hid_t object, const char* name, const std::string& where, H5T_class_t expected,
                      std::size_t max_bytes, std::size_t& bytes, const std::string& source) {
  const htri_t exists = H5Aexists(object, name);
  if (exists == 0) refuse(source, where + " is missing (this version writes it)");
  Handle attribute(exists > 0 ? H5Aopen(object, name, H5P_DEFAULT) : H5I_INVALID_HID, H5Aclose);
  if (!attribute.ok()) refuse(source, where + " cannot be read (damaged)");
  Handle space(H5Aget_space(attribute.get()), H5Sclose);
  if (!space.ok() || H5Sget_simple_extent_type(space.get()) != H5S_SCALAR)
    refuse(source, where + " is not a single value");
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  const char* const kind = expected == H5T_STRING ? "a fixed-length string" : "an integer";
  if (!type.ok() || H5Tget_class(type.get()) != expected ||
      (expected == H5T_STRING && H5Tis_variable_str(type.get()) != 0))
    refuse(source, where + " is not " + kind + " (this version writes one)");
  bytes = H5Tget_size(type.get());
  if (bytes == 0 || bytes > max_bytes) {
    refuse(source,
           where + " is " + kind + " of " + std::to_string(bytes) + " bytes, more than this version writes");
  }
  return attribute;
}

// A fixed-length string attribute (at most 64 bytes), trailing NULs dropped.
std::string string_attribute(hid_t object, const char* name, const std::string& where,
                             const std::string& source) {
  std::size_t bytes = 0;
  Handle attribute = open_attribute(object, name, where, H5T_STRING, 64, bytes, source);
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  std::array<char, 64> text{};
  if (!type.ok() || H5Aread(attribute.get(), type.get(), text.data()) < 0)
    refuse(source, where + " cannot be read (damaged)");
  std::string value(text.data(), bytes);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

// An integer attribute of 1, 2, 4 or 8 bytes, signed or not, either byte order, as its decimal text: read
// with its own type (no conversion) and decoded here.
std::string integer_attribute(hid_t object, const char* name, const std::string& where,
                              const std::string& source) {
  std::size_t bytes = 0;
  Handle attribute = open_attribute(object, name, where, H5T_INTEGER, 8, bytes, source);
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  std::array<unsigned char, 8> raw{};
  const H5T_order_t order = type.ok() ? H5Tget_order(type.get()) : H5T_ORDER_ERROR;
  const H5T_sign_t sign = type.ok() ? H5Tget_sign(type.get()) : H5T_SGN_ERROR;
  if ((bytes != 1 && bytes != 2 && bytes != 4 && bytes != 8) ||
      (order != H5T_ORDER_LE && order != H5T_ORDER_BE) || (sign != H5T_SGN_NONE && sign != H5T_SGN_2) ||
      H5Tget_precision(type.get()) != 8 * bytes || H5Tget_offset(type.get()) != 0)
    refuse(source, where + " is not an integer of 1, 2, 4 or 8 bytes");
  if (H5Aread(attribute.get(), type.get(), raw.data()) < 0)
    refuse(source, where + " cannot be read (damaged)");
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < bytes; ++i) {
    const std::size_t at = order == H5T_ORDER_LE ? bytes - 1 - i : i;  // most significant byte first
    value = (value << 8) | raw[at];
  }
  const bool negative = sign == H5T_SGN_2 && (value >> (8 * bytes - 1)) != 0;
  if (!negative) return std::to_string(value);
  const std::uint64_t magnitude = bytes == 8 ? ~value + 1 : (std::uint64_t{1} << (8 * bytes)) - value;
  std::string text(1, '-');  // built by appends: GCC 12 warns wrongly on "-" + std::string
  return text.append(std::to_string(magnitude));
}

// Refuses the file unless `got` is `expected` (each as its text: a string quoted, a number as it is).
void require_attribute(const std::string& where, const std::string& got, const std::string& expected,
                       bool quoted, const std::string& source) {
  if (got == expected) return;
  const auto shown = [quoted](const std::string& text) {
    if (!quoted) return text;
    std::string q("\"");
    return q.append(text).append("\"");
  };
  std::string what(where);
  what.append(" is ").append(shown(got)).append(", this version writes ").append(shown(expected));
  refuse(source, what);
}

// A dataset's chunks read raw (H5Dread_chunk) and decoded here: inflated by libdeflate (the same zlib
// stream, RFC 1950, that HDF5's deflate filter writes, at about three times zlib's speed) and unshuffled.
// HDF5's own pipeline would do the same under its global lock; this way the decoding of one file runs
// beside another thread's. Returns false, having read nothing, for any layout but the one this library
// writes (chunked, shuffle then deflate, an integer or float64 little-endian column), which HDF5 then reads.
class DirectChunks {
 public:
  DirectChunks() : inflater_(libdeflate_alloc_decompressor()) {}
  ~DirectChunks() { libdeflate_free_decompressor(inflater_); }
  DirectChunks(const DirectChunks&) = delete;
  DirectChunks& operator=(const DirectChunks&) = delete;

  // `out` (`samples` values) as doubles: integers over `power` (1 for a float column); `type` is the
  // dataset's.
  bool read_measured(hid_t dataset, hid_t type, std::size_t samples, double power, double* out) {
    damaged_chunk_.reset();
    const bool i32 = H5Tequal(type, H5T_STD_I32LE) > 0;
    const bool i64 = !i32 && H5Tequal(type, H5T_STD_I64LE) > 0;
    const bool f64 = !i32 && !i64 && H5Tequal(type, H5T_IEEE_F64LE) > 0;
    if (f64) return read_bytes(dataset, samples, 8, reinterpret_cast<unsigned char*>(out));
    if (!i32 && !i64) return false;
    const std::size_t element = i32 ? 4 : 8;
    values_.resize(samples * element);
    if (!read_bytes(dataset, samples, element, values_.data())) return false;
    const unsigned char* const from = values_.data();
    if (i32) {
      for (std::size_t i = 0; i < samples; ++i) {
        std::int32_t v;
        std::memcpy(&v, from + 4 * i, 4);
        out[i] = static_cast<double>(v) / power;
      }
    } else {
      for (std::size_t i = 0; i < samples; ++i) {
        std::int64_t v;
        std::memcpy(&v, from + 8 * i, 8);
        out[i] = static_cast<double>(v) / power;
      }
    }
    return true;
  }

  // The first sample of a chunk in this library's layout whose stream does not inflate to exactly the chunk's
  // bytes (cut short, two streams, damaged), from the last read that returned false; HDF5's own deflate
  // filter would hand on such a chunk with its missing samples undefined, so the file is refused instead.
  [[nodiscard]] std::optional<std::size_t> damaged_chunk() const { return damaged_chunk_; }

  // `samples` elements of `element` bytes each, little-endian as stored, into `out`.
  bool read_bytes(hid_t dataset, std::size_t samples, std::size_t element, unsigned char* out) {
    damaged_chunk_.reset();
    if (inflater_ == nullptr || samples == 0 || std::endian::native != std::endian::little) return false;
    hsize_t chunk_samples = 0;
    if (!shuffled_deflate_chunks(dataset, chunk_samples)) return false;
    const std::size_t chunk_bytes = static_cast<std::size_t>(chunk_samples) * element;
    raw_.resize(chunk_bytes);
    plain_.resize(chunk_bytes);
    for (hsize_t first = 0; first < samples; first += chunk_samples) {
      hsize_t stored = 0;
      const hsize_t offset[1] = {first};
      if (H5Dget_chunk_storage_size(dataset, offset, &stored) < 0 || stored == 0 ||
          stored > 2 * chunk_bytes + 1024)
        return false;
      compressed_.resize(static_cast<std::size_t>(stored));
      std::uint32_t skipped_filters = 0;
      if (H5Dread_chunk(dataset, H5P_DEFAULT, offset, &skipped_filters, compressed_.data()) < 0 ||
          skipped_filters != 0)
        return false;
      std::size_t inflated = 0;
      if (libdeflate_zlib_decompress(inflater_, compressed_.data(), compressed_.size(), raw_.data(),
                                     chunk_bytes, &inflated) != LIBDEFLATE_SUCCESS ||
          inflated != chunk_bytes) {
        damaged_chunk_ = static_cast<std::size_t>(first);
        return false;
      }
      const std::size_t count =
          std::min<std::size_t>(static_cast<std::size_t>(chunk_samples), samples - first);
      if (element == 1) {
        std::memcpy(out + first, raw_.data(), count);
      } else {
        unshuffle(raw_.data(), plain_.data(), element, static_cast<std::size_t>(chunk_samples));
        std::memcpy(out + first * element, plain_.data(), count * element);
      }
    }
    return true;
  }

 private:
  // Chunked in one dimension, filters exactly shuffle then deflate.
  static bool shuffled_deflate_chunks(hid_t dataset, hsize_t& chunk_samples) {
    Handle create(H5Dget_create_plist(dataset), H5Pclose);
    if (!create.ok() || H5Pget_layout(create.get()) != H5D_CHUNKED) return false;
    hsize_t chunk[1] = {0};
    if (H5Pget_chunk(create.get(), 1, chunk) != 1 || chunk[0] == 0 || chunk[0] > (hsize_t{1} << 24))
      return false;
    if (H5Pget_nfilters(create.get()) != 2) return false;
    const H5Z_filter_t expected[2] = {H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE};
    for (unsigned i = 0; i < 2; ++i) {
      unsigned flags = 0;
      std::size_t values = 0;
      unsigned int filter_info = 0;
      if (H5Pget_filter2(create.get(), i, &flags, &values, nullptr, 0, nullptr, &filter_info) != expected[i])
        return false;
    }
    chunk_samples = chunk[0];
    return true;
  }

  // HDF5's shuffle (byte k of every element, then byte k + 1, ...) undone: each element's bytes gathered
  // from the byte planes in turn, so that reads and writes both run forwards (a store a byte at a stride is
  // several times slower).
  template <std::size_t kElement>
  static void unshuffle_fixed(const unsigned char* in, unsigned char* out, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t byte = 0; byte < kElement; ++byte) out[i * kElement + byte] = in[byte * count + i];
    }
  }
  static void unshuffle(const unsigned char* in, unsigned char* out, std::size_t element, std::size_t count) {
    if (element == 4) return unshuffle_fixed<4>(in, out, count);
    if (element == 8) return unshuffle_fixed<8>(in, out, count);
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t byte = 0; byte < element; ++byte) out[i * element + byte] = in[byte * count + i];
    }
  }

  libdeflate_decompressor* inflater_;
  std::vector<unsigned char> compressed_, raw_, plain_, values_;
  std::optional<std::size_t> damaged_chunk_;
};

class TraceFileReader {
 public:
  TraceFileReader(hid_t file, std::size_t samples, const std::string& source)
      : file_(file), samples_(samples), source_(source), direct_(thread_direct_chunks()) {}

  // A dataset of `samples_` elements stored as one of `types` exactly: only the types this library writes are
  // read, so HDF5 never converts from a type a damaged file describes.
  Handle open(const char* name, std::initializer_list<hid_t> types) const {
    Handle dataset = open_column(file_, name, source_);
    Handle space(H5Dget_space(dataset.get()), H5Sclose);
    hsize_t dims[1] = {0};
    if (!space.ok() || H5Sget_simple_extent_ndims(space.get()) != 1 ||
        H5Sget_simple_extent_dims(space.get(), dims, nullptr) != 1 || dims[0] != samples_) {
      refuse(source_, std::string("column '") + name + "' does not hold " + std::to_string(samples_) +
                          " samples (as the time column does)");
    }
    Handle type(H5Dget_type(dataset.get()), H5Tclose);
    const bool known = type.ok() && std::any_of(types.begin(), types.end(),
                                                [&type](hid_t t) { return H5Tequal(type.get(), t) > 0; });
    if (!known) refuse(source_, std::string("column '") + name + "' is not of a type a trace file holds");
    return dataset;
  }

  // Read by HDF5 when the direct read did not: refused when the direct read found a damaged chunk.
  void read(const Handle& dataset, const char* name, hid_t memory_type, void* out) const {
    if (const std::optional<std::size_t> first = direct_.damaged_chunk()) {
      refuse(source_,
             std::string("column '") + name + "': its chunk from sample " + std::to_string(*first + 1) +
                 " does not inflate to the chunk's size (damaged, cut or forged: its samples would be "
                 "undefined)");
    }
    if (samples_ > 0 && H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0)
      refuse(source_, std::string("column '") + name + "' cannot be read (damaged or of another type)");
  }

  // A measured column: integers over 10^`decimals` (the version's, which the column's attribute repeats for
  // other readers), or doubles; every value finite when `finite`.
  // Its attributes say the same to other readers (h5py divides by 10 ** decimals): `unit` must be its unit in
  // the table of a trace's columns, and `decimals` `decimals` on an integer column and absent on a column of
  // doubles, or the file is refused.
  std::vector<double> measured(const char* name, int decimals, bool finite) {
    Handle dataset = open(name, {H5T_STD_I32LE, H5T_STD_I64LE, H5T_IEEE_F64LE});
    Handle type(H5Dget_type(dataset.get()), H5Tclose);
    const bool integers = H5Tget_class(type.get()) == H5T_INTEGER;
    const std::string unit_path = attribute_path(name, "unit");
    require_attribute(unit_path, string_attribute(dataset.get(), "unit", unit_path, source_), unit_of(name),
                      true, source_);
    const std::string decimals_path = attribute_path(name, "decimals");
    if (integers) {
      require_attribute(decimals_path, integer_attribute(dataset.get(), "decimals", decimals_path, source_),
                        std::to_string(decimals), false, source_);
    } else if (H5Aexists(dataset.get(), "decimals") != 0) {
      refuse(source_, decimals_path +
                          " is on a column of doubles, where this version writes none (the values are not "
                          "scaled)");
    }
    // The integer (exact in a double) over an exact power of ten, one correctly rounded division: the value
    // the CSV's text of the same digits parses to.
    static constexpr double kPowers[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                         1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};  // each exact
    const double power = integers ? kPowers[decimals] : 1.0;
    std::vector<double> values(samples_);
    if (!direct_.read_measured(dataset.get(), type.get(), samples_, power, values.data())) {
      read(dataset, name, H5T_NATIVE_DOUBLE, values.data());
      if (power != 1.0) {
        for (double& v : values) v /= power;
      }
    }
    if (finite) {
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i]))
          refuse(source_,
                 std::string("column '") + name + "', sample " + std::to_string(i + 1) + ": not finite");
      }
    }
    return values;
  }

  // A column of whole numbers; `stored`: the file type this library writes it as, read without conversion.
  template <typename T>
  std::vector<T> whole(const char* name, hid_t stored, hid_t memory_type) {
    Handle dataset = open(name, {stored});
    std::vector<T> values(samples_);
    if (!direct_.read_bytes(dataset.get(), samples_, sizeof(T),
                            reinterpret_cast<unsigned char*>(values.data())))
      read(dataset, name, memory_type, values.data());
    return values;
  }

  std::vector<std::uint8_t> states() {
    Handle stored = state_type(H5T_STD_U8LE);
    Handle dataset = open("state", {stored.get()});
    Handle memory = state_type(H5T_NATIVE_UINT8);
    std::vector<std::uint8_t> values(samples_);
    if (!direct_.read_bytes(dataset.get(), samples_, 1, values.data()))
      read(dataset, "state", memory.get(), values.data());
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (values[i] > static_cast<std::uint8_t>(InteractionState::writing))
        refuse(source_, "column 'state', sample " + std::to_string(i + 1) + ": not SS, AS, CS or WS");
    }
    return values;
  }

 private:
  hid_t file_;
  std::size_t samples_;
  const std::string& source_;
  DirectChunks& direct_;

  // One decoder a thread, kept: its buffers grow to the largest chunk read and are reused by every file after
  // (fresh ones for each file cost page faults of their own).
  static DirectChunks& thread_direct_chunks() {
    thread_local DirectChunks chunks;
    return chunks;
  }
};

}  // namespace

TraceColumns parse_trace_hdf5(std::string_view bytes, const std::string& source, TraceColumnSet columns) {
  check_user_block(bytes, source);
  silence_hdf5();
  Handle access = memory_file_access(4096);
  // HDF5 copies the image (it may not keep a caller's buffer); a trace is a few hundred kilobytes.
  if (H5Pset_file_image(access.get(), const_cast<char*>(bytes.data()), bytes.size()) < 0)
    refuse(source, "HDF5 cannot take the file's image (out of memory?)");
  Handle file(H5Fopen(image_name().c_str(), H5F_ACC_RDONLY, access.get()), H5Fclose);
  if (!file.ok()) refuse(source, "HDF5 cannot open it (damaged)");
  // What the file is, its version and so its layout, are in the header checked above. HDF5's attributes (the
  // root's format, version and samples, a column's unit and decimals) say the same to other readers, which
  // read the values by them (docs/python.md): each must be what this version writes, or the file is refused
  // naming it, so that no file reads as one thing here and as another there. They are decoded only now that
  // the CRC-32 has matched (accidental damage to a header is where HDF5 1.10 crashed), and each is checked
  // before it is read (above: open_attribute).
  const hid_t root = file.get();
  const std::string format_path = attribute_path(nullptr, "format");
  require_attribute(format_path, string_attribute(root, "format", format_path, source), std::string(kFormat),
                    true, source);
  const std::string version_path = attribute_path(nullptr, "version");
  require_attribute(version_path, integer_attribute(root, "version", version_path, source),
                    std::to_string(kVersion), false, source);
  // The samples are the time column's length, which the root's `samples` repeats.
  const std::size_t samples = dataset_length(file.get(), "t", source);
  const std::string declared = integer_attribute(root, "samples", attribute_path(nullptr, "samples"), source);
  if (declared != std::to_string(samples)) {
    refuse(source, "attribute /samples is " + declared + ", but the time column holds " +
                       std::to_string(samples) + " samples");
  }
  // Bounded before any column is allocated: by what the file's bytes could hold (deflate inflates at most
  // 1032-fold, a sample takes at least 4 bytes of the time column) and by kMaxTraceSamples.
  if (samples > kMaxTraceSamples || samples / 1032 > bytes.size() / 4) {
    refuse(source,
           std::to_string(samples) + " samples, more than " +
               (samples > kMaxTraceSamples ? "a trace file holds (" + std::to_string(kMaxTraceSamples) + ")"
                                           : "its " + std::to_string(bytes.size()) + " bytes can hold"));
  }
  TraceFileReader in(file.get(), samples, source);
  TraceColumns c;
  c.time_s = in.measured("t", kTraceTimeDecimals, true);
  c.x_m = in.measured("x", kTracePositionDecimals, true);
  c.y_m = in.measured("y", kTracePositionDecimals, true);
  c.z_m = in.measured("z", kTracePositionDecimals, true);
  c.fx_n = in.measured("fx", kTraceForceDecimals, false);
  c.fy_n = in.measured("fy", kTraceForceDecimals, false);
  if (columns == TraceColumnSet::pen) return c;
  c.fz_n = in.measured("fz", kTraceForceDecimals, false);
  c.state = in.states();
  c.stroke = in.whole<std::uint32_t>("stroke", H5T_STD_U32LE, H5T_NATIVE_UINT32);
  c.element = in.whole<std::uint32_t>("element", H5T_STD_U32LE, H5T_NATIVE_UINT32);
  c.attempt = in.whole<std::int32_t>("attempt", H5T_STD_I32LE, H5T_NATIVE_INT32);
  c.rewritten = in.whole<std::uint8_t>("rewritten", H5T_STD_U8LE, H5T_NATIVE_UINT8);
  for (std::size_t i = 0; i < c.rewritten.size(); ++i) {
    if (c.rewritten[i] > 1)
      refuse(source, "column 'rewritten', sample " + std::to_string(i + 1) + ": not 0 or 1");
  }
  return c;
}

std::string read_trace_hdf5_bytes(const std::filesystem::path& file, std::uintmax_t max_file_bytes) {
  // The one reader of a bounded input file: a missing file, a device (/dev/zero), a FIFO or a folder is
  // named as what it is, never read.
  return read_regular_file(file, max_file_bytes);
}

TraceColumns read_trace_hdf5(const std::filesystem::path& file, std::uintmax_t max_file_bytes,
                             TraceColumnSet columns) {
  return parse_trace_hdf5(read_trace_hdf5_bytes(file, max_file_bytes), file.string(), columns);
}

std::vector<TrialSample> trial_samples(const TraceColumns& c) {
  const std::size_t n = c.size();
  for (const std::size_t size :
       {c.x_m.size(), c.y_m.size(), c.z_m.size(), c.fx_n.size(), c.fy_n.size(), c.fz_n.size(), c.state.size(),
        c.stroke.size(), c.element.size(), c.attempt.size(), c.rewritten.size()}) {
    if (size != n) throw InvalidArgument("trial_samples: the columns differ in length (read them all)");
  }
  std::vector<TrialSample> trace(n);
  for (std::size_t i = 0; i < n; ++i) {
    TrialSample& s = trace[i];
    s.time_s = c.time_s[i];
    s.position_m = Vec3(c.x_m[i], c.y_m[i], c.z_m[i]);
    s.force_n = Vec3(c.fx_n[i], c.fy_n[i], c.fz_n[i]);
    s.state = static_cast<InteractionState>(c.state[i]);
    s.stroke = c.stroke[i];
    s.element = c.element[i];
    s.attempt = c.attempt[i];
    s.rewritten = c.rewritten[i] != 0;
  }
  return trace;
}

}  // namespace calligraphy
