// Reads the corpus store (docs/corpus.md), read whole into memory. Every offset and size is
// checked against the file before it is used; every failure is a DataError naming the file and offset.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "core/whole_file.hpp"
#include "model/bundled_corpus_store.hpp"
#include "model/corpus_store_format.hpp"
#include "model/corpus_store_outlines.hpp"

namespace calligraphy {

using namespace store;

struct CorpusStore::Data {
  std::string name;
  const std::uint8_t* bytes = nullptr;
  std::size_t size = 0;
  std::string owned;  // the store's bytes, read whole (open) or copied (from_bytes)
  CorpusStoreInfo info;
  const std::uint8_t* index = nullptr;
  const std::uint8_t* records = nullptr;
  std::array<double, kTypicalStrokeCount> default_factors{};
  std::array<double, kTypicalStrokeCount> corner_factors{};

  Data() = default;
  Data(const Data&) = delete;
  Data& operator=(const Data&) = delete;
  ~Data() = default;

  [[noreturn]] void fail(std::size_t offset, const std::string& what) const {
    throw DataError(name + ": offset " + std::to_string(offset) + ": " + what);
  }

  [[nodiscard]] std::uint32_t code_point_at(std::size_t k) const {
    return get_u32(index + kIndexEntryBytes * k);
  }
  [[nodiscard]] std::size_t record_begin(std::size_t k) const {
    return get_u32(index + kIndexEntryBytes * k + 4);
  }
  [[nodiscard]] std::size_t record_end(std::size_t k) const {
    return k + 1 < info.character_count ? record_begin(k + 1) : info.record_bytes;
  }
  /// Index of the entry for cp, or character_count when absent.
  [[nodiscard]] std::size_t find(char32_t cp) const {
    std::size_t lo = 0;
    std::size_t hi = info.character_count;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (code_point_at(mid) < cp) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo < info.character_count && code_point_at(lo) == cp ? lo : info.character_count;
  }

  void validate();
  /// The character; its outlines' paths into `outlines` when not null (they are checked either way).
  [[nodiscard]] Character decode(std::size_t k, std::vector<std::string>* outlines = nullptr) const;
};

void CorpusStore::Data::validate() {
  if (size < kHeaderBytes)
    fail(size, "file too short for a corpus store header (" + std::to_string(size) + " bytes)");
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes)) fail(0, "not a calligraphy corpus store (bad magic)");
  if (get_u32(bytes + kOffHeaderCrc) != crc32(std::span(bytes, kOffHeaderCrc)))
    fail(0, "header checksum mismatch");
  info.version_major = get_u16(bytes + kOffVersionMajor);
  info.version_minor = get_u16(bytes + kOffVersionMinor);
  if (info.version_major != kVersionMajor) {
    fail(kOffVersionMajor, "format version " + std::to_string(info.version_major) + "." +
                               std::to_string(info.version_minor) + " is not supported (this reader reads " +
                               std::to_string(kVersionMajor) + ".x)");
  }
  if (get_u32(bytes + kOffHeaderSize) != kHeaderBytes) fail(kOffHeaderSize, "unexpected header size");
  const std::uint32_t flags = get_u32(bytes + kOffFlags);
  if ((flags & ~kKnownFlags) != 0) fail(kOffFlags, "unknown flags");
  info.medians = (flags & kFlagMedians) != 0;
  info.outlines = (flags & kFlagOutlines) != 0;
  info.character_count = get_u32(bytes + kOffCount);
  info.steps_per_unit = static_cast<int>(get_u32(bytes + kOffSteps));
  const int s = info.steps_per_unit;
  if (s != 1 && s != 2 && s != 4 && s != 8 && s != 16)
    fail(kOffSteps, "quantisation steps per unit out of range");
  info.fit_tolerance = get_f32(bytes + kOffTolerance);
  const std::uint64_t index_offset = get_u64(bytes + kOffIndex);
  const std::uint64_t records_offset = get_u64(bytes + kOffRecords);
  const std::uint64_t records_size = get_u64(bytes + kOffRecordsSize);
  if (index_offset != kHeaderBytes + kDefaultsBytes) fail(kOffIndex, "unexpected index offset");
  if (records_offset != index_offset + kIndexEntryBytes * std::uint64_t{info.character_count}) {
    fail(kOffRecords,
         "records offset does not follow the index of " + std::to_string(info.character_count) + " entries");
  }
  if (records_offset > size || records_size != size - records_offset) {
    fail(kOffRecordsSize, "file is " + std::to_string(size) + " bytes, header says " +
                              std::to_string(records_offset) + " + " + std::to_string(records_size) +
                              " (truncated or extended)");
  }
  info.file_bytes = size;
  info.header_bytes = index_offset;
  info.index_bytes = records_offset - index_offset;
  info.record_bytes = records_size;
  if (get_u32(bytes + kOffTablesCrc) !=
      crc32(std::span(bytes + kHeaderBytes, records_offset - kHeaderBytes))) {
    fail(kHeaderBytes, "checksum mismatch in the default-factor table or the index");
  }
  index = bytes + index_offset;
  records = bytes + records_offset;
  for (std::size_t id = 0; id < kTypicalStrokeCount; ++id) {
    default_factors[id] = get_f64(bytes + kHeaderBytes + 16 * id);
    corner_factors[id] = get_f64(bytes + kHeaderBytes + 16 * id + 8);
    if (!std::isfinite(default_factors[id]) || !std::isfinite(corner_factors[id]))
      fail(kHeaderBytes + 16 * id, "default or corner attraction factor not finite");
  }
  for (std::size_t k = 0; k < info.character_count; ++k) {
    const std::size_t at = index_offset + kIndexEntryBytes * k;
    if (code_point_at(k) > 0x10FFFF || (k > 0 && code_point_at(k) <= code_point_at(k - 1))) {
      fail(at, "index entry " + std::to_string(k) + ": code points not strictly increasing Unicode scalars");
    }
    if ((k == 0 && record_begin(k) != 0) || record_begin(k) >= record_end(k) ||
        record_end(k) > records_size) {
      fail(at + 4, "index entry " + std::to_string(k) + ": record offsets out of order or out of the file");
    }
  }
}

Character CorpusStore::Data::decode(std::size_t k, std::vector<std::string>* outlines) const {
  const char32_t cp = code_point_at(k);
  const std::size_t begin = record_begin(k);
  const std::span<const std::uint8_t> record(records + begin, record_end(k) - begin);
  const std::size_t file_offset = static_cast<std::size_t>(records - bytes) + begin;
  const auto bad = [&](const std::string& what) {
    fail(file_offset, "record of character " + describe_character(cp) + ": " + what);
  };
  if (get_u32(index + kIndexEntryBytes * k + 8) != crc32(record)) bad("checksum mismatch");

  BitReader in(record);
  const auto get = [&](int bits) {
    std::uint64_t v = 0;
    if (!in.get(bits, v)) bad("ends early at bit " + std::to_string(in.bit_position()));
    return v;
  };
  const double scale = 1.0 / info.steps_per_unit;
  Character character;
  character.code_point = cp;
  character.source = name + "#" + describe_character(cp);
  const std::size_t stroke_count = get(8);
  if (stroke_count == 0) bad("no strokes");
  character.strokes.resize(stroke_count);
  std::int64_t x = 0;
  std::int64_t y = 0;
  std::vector<std::array<std::int64_t, 2>> median_origins(stroke_count);
  for (std::size_t s = 0; s < stroke_count; ++s) {
    Stroke& stroke = character.strokes[s];
    stroke.typical_id = static_cast<int>(get(6));
    if (stroke.typical_id < 1 || stroke.typical_id > 39)
      bad("stroke " + std::to_string(s + 1) + ": typical ID out of range");
    std::size_t n = get(4) + 1;
    if (n == 16) n += get(8);
    const unsigned flags = static_cast<unsigned>(get(2));
    std::array<int, 15 + 256> degrees{};
    for (std::size_t e = 0; e < n; ++e) degrees[e] = static_cast<int>(get(2)) + 1;
    std::array<bool, 15 + 256> detached{};
    if (flags & kDetachedElements) {
      for (std::size_t e = 1; e < n; ++e) detached[e] = get(1) != 0;
    }
    const auto next_point = [&](int width) {
      x += unzigzag(get(width));
      y += unzigzag(get(width));
      return Vec2(static_cast<double>(x) * scale, static_cast<double>(y) * scale);
    };
    const int start_width = static_cast<int>(get(5));
    Vec2 previous = next_point(start_width);
    median_origins[s] = {x / info.steps_per_unit, y / info.steps_per_unit};
    const int width = static_cast<int>(get(5));
    stroke.elements.resize(n);
    for (std::size_t e = 0; e < n; ++e) {
      StrokeElement& element = stroke.elements[e];
      element.degree = degrees[e];
      element.kind = element.degree == 1 ? ElementKind::line : ElementKind::bezier;
      element.control[0] = detached[e] ? next_point(width) : previous;
      for (int i = 1; i <= element.degree; ++i)
        element.control[static_cast<std::size_t>(i)] = next_point(width);
      previous = element.end();
    }
    if (flags & kExplicitFactors) {
      const auto id = static_cast<std::size_t>(stroke.typical_id - 1);
      const bool palette = get(1) == 1;
      stroke.attraction_factors.resize(n + 1);
      for (double& f : stroke.attraction_factors) {
        if (palette) {
          f = get(1) == 1 ? corner_factors[id] : default_factors[id];
          continue;
        }
        const std::uint64_t bits = get(64);
        std::memcpy(&f, &bits, sizeof f);
        if (!std::isfinite(f)) bad("stroke " + std::to_string(s + 1) + ": attraction factor not finite");
      }
    } else {
      stroke.attraction_factors.assign(n + 1,
                                       default_factors[static_cast<std::size_t>(stroke.typical_id - 1)]);
    }
  }
  if (info.medians) {
    for (std::size_t s = 0; s < stroke_count; ++s) {
      std::size_t n = get(5);
      if (n == kMedianCountEscape) {
        n = get(kMedianCountExtensionBits);
        if (n < kMedianCountEscape) bad("stroke " + std::to_string(s + 1) + ": median count not minimal");
      }
      if (n == 0) continue;
      std::vector<Vec2>& median = character.strokes[s].median;
      median.reserve(n);
      const int shift = static_cast<int>(get(2));
      if (shift == kMedianRawMode) {
        for (std::size_t i = 0; i < n; ++i) {
          std::array<double, 2> xy{};
          for (double& v : xy) {
            const std::uint64_t bits = get(64);
            std::memcpy(&v, &bits, sizeof v);
            if (!std::isfinite(v) || std::abs(v) > static_cast<double>(kMaxMedianCoordinate))
              bad("stroke " + std::to_string(s + 1) + ": median coordinate not finite or out of range");
          }
          median.emplace_back(xy[0], xy[1]);
        }
        continue;
      }
      const double unit = 1.0 / static_cast<double>(1 << shift);
      std::int64_t mx = median_origins[s][0] * (std::int64_t{1} << shift);
      std::int64_t my = median_origins[s][1] * (std::int64_t{1} << shift);
      const auto add_point = [&] {
        if (std::abs(mx) > kMaxMedianCoordinate || std::abs(my) > kMaxMedianCoordinate)
          bad("stroke " + std::to_string(s + 1) + ": median point out of range");
        median.emplace_back(static_cast<double>(mx) * unit, static_cast<double>(my) * unit);
      };
      const int start_width = static_cast<int>(get(5));
      mx += unzigzag(get(start_width));
      my += unzigzag(get(start_width));
      add_point();
      if (n == 1) continue;
      const int width_x = static_cast<int>(get(5));
      const int width_y = static_cast<int>(get(5));
      for (std::size_t i = 1; i < n; ++i) {
        mx += unzigzag(get(width_x));
        my += unzigzag(get(width_y));
        add_point();
      }
    }
  }
  if (info.outlines) {
    std::vector<std::string> paths = decode_outlines(in, stroke_count, outlines != nullptr, bad);
    if (outlines != nullptr) *outlines = std::move(paths);
  }
  // The writer pads the last byte with zero bits and writes nothing after.
  std::uint64_t padding = 0;
  if (in.remaining() >= 8 || !in.get(static_cast<int>(in.remaining()), padding) || padding != 0) {
    bad("unexpected bytes after the last stroke");
  }
  return character;
}

double CorpusStoreInfo::max_quantisation_error() const {
  return steps_per_unit > 0 ? std::sqrt(2.0) / (2.0 * steps_per_unit) : 0.0;
}

CorpusStore CorpusStore::open(const std::filesystem::path& path) {
  auto data = std::make_shared<Data>();
  data->name = path.string();
  // Read whole, not mapped: a file truncated by another process while mapped would end the process with
  // SIGBUS at the next access, and a store is a few megabytes. A FIFO or device is refused unread.
  data->owned = read_regular_file(path, kMaxCorpusStoreBytes);
  data->bytes = reinterpret_cast<const std::uint8_t*>(data->owned.data());
  data->size = data->owned.size();
  data->validate();
  return CorpusStore(std::move(data));
}

CorpusStore CorpusStore::from_bytes(std::span<const std::uint8_t> bytes, const std::string& name) {
  auto data = std::make_shared<Data>();
  data->name = name;
  data->owned.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  data->bytes = reinterpret_cast<const std::uint8_t*>(data->owned.data());
  data->size = data->owned.size();
  data->validate();
  return CorpusStore(std::move(data));
}

const CorpusStore& CorpusStore::bundled() {
  // Checked once; a failure is thrown again to every caller (static initialisation is retried).
  static const CorpusStore store = [] {
    const detail::BundledCorpusStore bundled = detail::bundled_corpus_store();
    auto data = std::make_shared<Data>();
    data->name = std::string("bundled:") + bundled.name;
    data->bytes = bundled.bytes.data();
    data->size = bundled.bytes.size();
    data->validate();
    return CorpusStore(std::move(data));
  }();
  return store;
}

const char* CorpusStore::bundled_sha256() { return detail::bundled_corpus_store().sha256; }

const CorpusStoreInfo& CorpusStore::info() const { return data_->info; }
const std::string& CorpusStore::name() const { return data_->name; }

bool CorpusStore::contains(char32_t cp) const { return data_->find(cp) < data_->info.character_count; }

std::vector<char32_t> CorpusStore::characters() const {
  std::vector<char32_t> out(data_->info.character_count);
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = data_->code_point_at(k);
  return out;
}

namespace {
[[noreturn]] void not_found(const std::string& name, char32_t cp, std::size_t count) {
  throw CharacterNotFound("character " + describe_character(cp) + " is not in the corpus store " + name +
                          " (" + std::to_string(count) + " characters)");
}
}  // namespace

std::size_t CorpusStore::record_bytes(char32_t cp) const {
  const std::size_t k = data_->find(cp);
  if (k == data_->info.character_count) not_found(data_->name, cp, k);
  return data_->record_end(k) - data_->record_begin(k);
}

Character CorpusStore::load(char32_t cp) const {
  const std::size_t k = data_->find(cp);
  if (k == data_->info.character_count) not_found(data_->name, cp, k);
  return data_->decode(k);
}

std::vector<std::string> CorpusStore::load_outline_paths(char32_t cp) const {
  const std::size_t k = data_->find(cp);
  if (k == data_->info.character_count) not_found(data_->name, cp, k);
  std::vector<std::string> paths;
  (void)data_->decode(k, &paths);
  return paths;
}

CorpusStoreStats corpus_store_stats(const CorpusStore& store) {
  CorpusStoreStats stats;
  for (char32_t cp : store.characters()) {
    try {
      const Character c = store.load(cp);
      ++stats.characters;
      stats.strokes += c.strokes.size();
      for (const Stroke& s : c.strokes) {
        stats.elements += s.elements.size();
        ++stats.strokes_by_typical_id[s.typical_id];
      }
    } catch (const DataError& e) {
      stats.errors.push_back(e.what());
    }
  }
  return stats;
}

}  // namespace calligraphy
