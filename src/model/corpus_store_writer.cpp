// Writes the corpus store (docs/corpus.md): header, table of default attraction factors, sorted index,
// bit-packed records of quantised, delta-coded control points with shared joints.
#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "model/corpus_store_format.hpp"
#include "model/corpus_store_outlines.hpp"

namespace calligraphy {
namespace {

using namespace store;

struct QPoint {
  std::int64_t x = 0;
  std::int64_t y = 0;
  bool operator==(const QPoint&) const = default;
};

class RecordEncoder {
 public:
  RecordEncoder(const Character& character, int steps, bool medians, const std::vector<std::string>* outlines)
      : character_(character), steps_(steps), medians_(medians), outlines_(outlines) {}

  std::vector<std::uint8_t> encode() {
    const auto& strokes = character_.strokes;
    if (strokes.empty() || strokes.size() > 255)
      fail("has " + std::to_string(strokes.size()) + " strokes (1-255)");
    out_.put(strokes.size(), 8);
    for (std::size_t s = 0; s < strokes.size(); ++s) encode_stroke(s);
    if (medians_) {
      for (std::size_t s = 0; s < strokes.size(); ++s) encode_median(s);
    }
    if (outlines_ != nullptr) {
      encode_outlines(out_, *outlines_, strokes.size(), [this](const std::string& what) { fail(what); });
    }
    return out_.take();
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw InvalidArgument("corpus store: character " + describe_character(character_.code_point) + " " +
                          what);
  }

  QPoint quantise(const Vec2& p, std::size_t stroke) const {
    const auto q = [&](double v) {
      const double scaled = std::round(v * steps_);
      if (!std::isfinite(scaled) || std::abs(scaled) > static_cast<double>(kMaxCoordinate)) {
        fail("stroke " + std::to_string(stroke + 1) + ": coordinate " + shortest_decimal(v) +
             " out of range");
      }
      return static_cast<std::int64_t>(scaled);
    };
    return {q(p.x()), q(p.y())};
  }

  void encode_stroke(std::size_t s) {
    const Stroke& stroke = character_.strokes[s];
    const std::string where = "stroke " + std::to_string(s + 1);
    if (stroke.typical_id < 1 || stroke.typical_id > 39) fail(where + ": typical ID out of range 1-39");
    const std::size_t n = stroke.elements.size();
    // count:4 holds 1..15 elements, count 15 and count_extension:8 16..271 (docs/corpus.md, "Record").
    if (n == 0 || n > 16 + 255)
      fail(where + ": " + std::to_string(n) + " elements, where a store's record holds 1-271");
    if (stroke.attraction_factors.size() != n + 1)
      fail(where + ": needs one attraction factor per feature point");

    // Control points in writing order; an element starting where the last ended shares that joint.
    std::vector<QPoint> points;
    std::vector<bool> detached(n, false);
    for (std::size_t k = 0; k < n; ++k) {
      const StrokeElement& e = stroke.elements[k];
      if (e.degree < 1 || e.degree > kMaxElementDegree || (e.degree == 1) != (e.kind == ElementKind::line)) {
        fail(where + ": element " + std::to_string(k + 1) + " has kind/degree out of range");
      }
      const QPoint start = quantise(e.start(), s);
      if (k == 0 || !(start == points.back())) {
        detached[k] = k > 0;
        points.push_back(start);
      }
      for (int i = 1; i <= e.degree; ++i)
        points.push_back(quantise(e.control[static_cast<std::size_t>(i)], s));
    }
    const bool any_detached = std::find(detached.begin(), detached.end(), true) != detached.end();
    const TypicalStroke& type = typical_stroke(stroke.typical_id);
    bool explicit_factors = false;  // some factor is not the ID's default
    bool palette = true;            // every factor is the ID's default or corner factor
    for (double f : stroke.attraction_factors) {
      if (!std::isfinite(f)) fail(where + ": attraction factor is not finite");
      explicit_factors |= f != type.default_attraction;
      palette &= f == type.default_attraction || f == type.corner_attraction;
    }

    out_.put(static_cast<std::uint64_t>(stroke.typical_id), 6);
    if (n - 1 < 15) {
      out_.put(n - 1, 4);
    } else {
      out_.put(15, 4);
      out_.put(n - 16, 8);
    }
    out_.put((explicit_factors ? kExplicitFactors : 0u) | (any_detached ? kDetachedElements : 0u), 2);
    for (const StrokeElement& e : stroke.elements) out_.put(static_cast<std::uint64_t>(e.degree - 1), 2);
    if (any_detached) {
      for (std::size_t k = 1; k < n; ++k) out_.put(detached[k] ? 1 : 0, 1);
    }
    // The start relative to the previous stroke's end, with its own width: strokes jump further than
    // control points within a stroke move.
    const auto put_delta = [&](const QPoint& from, const QPoint& to, int width) {
      out_.put(zigzag(to.x - from.x), width);
      out_.put(zigzag(to.y - from.y), width);
    };
    const int start_width =
        std::max(bit_width(zigzag(points[0].x - previous_.x)), bit_width(zigzag(points[0].y - previous_.y)));
    out_.put(static_cast<std::uint64_t>(start_width), 5);
    put_delta(previous_, points[0], start_width);
    int width = 0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      width = std::max({width, bit_width(zigzag(points[i].x - points[i - 1].x)),
                        bit_width(zigzag(points[i].y - points[i - 1].y))});
    }
    out_.put(static_cast<std::uint64_t>(width), 5);
    for (std::size_t i = 1; i < points.size(); ++i) put_delta(points[i - 1], points[i], width);
    if (explicit_factors) {
      out_.put(palette ? 1 : 0, 1);
      for (double f : stroke.attraction_factors) {
        if (palette) {
          out_.put(f == type.default_attraction ? 0 : 1, 1);
        } else {
          out_.put(double_bits(f), 64);
        }
      }
    }
    previous_ = points.back();
    // The median's reference: the stroke's start in whole data units (truncated towards zero).
    median_origins_.push_back({points[0].x / steps_, points[0].y / steps_});
  }

  // The median in units of 2^-shift data units, shift 0-2 the smallest that holds every coordinate exactly
  // (hanzi-writer-data: whole units, in 31 characters quarter units): its first point relative to the
  // stroke's start, the others to the point before, x and y each in its own width. Else (2 strokes of
  // hanzi-writer-data, in ninths of a unit) mode 3: each coordinate as a float64, so that none is changed.
  void encode_median(std::size_t s) {
    const std::vector<Vec2>& median = character_.strokes[s].median;
    const std::string where = "stroke " + std::to_string(s + 1) + ": median";
    if (median.size() >= (std::size_t{1} << kMedianCountExtensionBits))
      fail(where + " has " + std::to_string(median.size()) + " points (at most 16383)");
    if (median.size() < kMedianCountEscape) {
      out_.put(median.size(), 5);
    } else {
      out_.put(kMedianCountEscape, 5);
      out_.put(median.size(), kMedianCountExtensionBits);
    }
    if (median.empty()) return;
    int shift = 0;
    const auto exact = [&](int k) {
      return std::all_of(median.begin(), median.end(), [k](const Vec2& p) {
        const double scale = static_cast<double>(1 << k);
        return std::nearbyint(p.x() * scale) == p.x() * scale &&
               std::nearbyint(p.y() * scale) == p.y() * scale;
      });
    };
    while (shift <= kMaxMedianShift && !exact(shift)) ++shift;
    out_.put(static_cast<std::uint64_t>(shift), 2);
    if (shift == kMedianRawMode) {
      for (const Vec2& p : median) {
        for (double v : {p.x(), p.y()}) {
          if (!std::isfinite(v) || std::abs(v) > static_cast<double>(kMaxMedianCoordinate))
            fail(where + ": coordinate " + shortest_decimal(v) + " out of range");
          out_.put(double_bits(v), 64);
        }
      }
      return;
    }
    std::vector<QPoint> points;
    for (const Vec2& p : median) {
      const auto round = [&](double v) {
        const double r = std::round(v * static_cast<double>(1 << shift));
        if (!std::isfinite(r) || std::abs(r) > static_cast<double>(kMaxMedianCoordinate))
          fail(where + ": coordinate " + shortest_decimal(v) + " out of range");
        return static_cast<std::int64_t>(r);
      };
      points.push_back({round(p.x()), round(p.y())});
    }
    const QPoint origin{median_origins_[s].x * (std::int64_t{1} << shift),
                        median_origins_[s].y * (std::int64_t{1} << shift)};
    const int start_width =
        std::max(bit_width(zigzag(points[0].x - origin.x)), bit_width(zigzag(points[0].y - origin.y)));
    out_.put(static_cast<std::uint64_t>(start_width), 5);
    out_.put(zigzag(points[0].x - origin.x), start_width);
    out_.put(zigzag(points[0].y - origin.y), start_width);
    if (points.size() < 2) return;
    int width_x = 0;
    int width_y = 0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      width_x = std::max(width_x, bit_width(zigzag(points[i].x - points[i - 1].x)));
      width_y = std::max(width_y, bit_width(zigzag(points[i].y - points[i - 1].y)));
    }
    out_.put(static_cast<std::uint64_t>(width_x), 5);
    out_.put(static_cast<std::uint64_t>(width_y), 5);
    for (std::size_t i = 1; i < points.size(); ++i) {
      out_.put(zigzag(points[i].x - points[i - 1].x), width_x);
      out_.put(zigzag(points[i].y - points[i - 1].y), width_y);
    }
  }

  const Character& character_;
  int steps_;
  bool medians_;
  const std::vector<std::string>* outlines_;  // null: the store holds no outlines
  BitWriter out_;
  QPoint previous_;
  std::vector<QPoint> median_origins_;
};

}  // namespace

std::vector<std::uint8_t> encode_corpus_store(std::span<const Character> characters,
                                              const CorpusStoreOptions& options) {
  return encode_corpus_store(characters, options, {});
}

std::vector<std::uint8_t> encode_corpus_store(std::span<const Character> characters,
                                              const CorpusStoreOptions& options,
                                              std::span<const std::vector<std::string>> outline_paths) {
  const int steps = options.steps_per_unit;
  if (steps != 1 && steps != 2 && steps != 4 && steps != 8 && steps != 16) {
    throw InvalidArgument("corpus store: steps_per_unit must be 1, 2, 4, 8 or 16, got " +
                          std::to_string(steps));
  }
  if (!(options.fit_tolerance >= 0.0) || !std::isfinite(options.fit_tolerance)) {
    throw InvalidArgument("corpus store: fit_tolerance must be finite and >= 0");
  }
  if (!outline_paths.empty() && outline_paths.size() != characters.size()) {
    throw InvalidArgument("corpus store: " + std::to_string(outline_paths.size()) + " outline lists for " +
                          std::to_string(characters.size()) + " characters");
  }
  // Outlines are stored when asked for and some character has them.
  const bool outlines = options.outlines && std::any_of(outline_paths.begin(), outline_paths.end(),
                                                        [](const auto& paths) { return !paths.empty(); });
  std::vector<std::size_t> sorted(characters.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) sorted[i] = i;
  std::sort(sorted.begin(), sorted.end(), [&](std::size_t a, std::size_t b) {
    return characters[a].code_point < characters[b].code_point;
  });
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (characters[sorted[i]].code_point == characters[sorted[i - 1]].code_point) {
      throw InvalidArgument("corpus store: character " +
                            describe_character(characters[sorted[i]].code_point) + " given twice");
    }
  }

  const std::size_t index_offset = kHeaderBytes + kDefaultsBytes;
  const std::size_t records_offset = index_offset + kIndexEntryBytes * sorted.size();
  std::vector<std::uint8_t> file(records_offset, 0);
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    const Character* c = &characters[sorted[k]];
    if (c->code_point > 0x10FFFF) throw InvalidArgument("corpus store: code point out of Unicode range");
    const std::size_t offset = file.size() - records_offset;
    if (offset > 0xFFFFFFFFu) throw InvalidArgument("corpus store: records exceed 4 GiB");
    const std::vector<std::uint8_t> record =
        RecordEncoder(*c, steps, options.medians, outlines ? &outline_paths[sorted[k]] : nullptr).encode();
    file.insert(file.end(), record.begin(), record.end());
    std::uint8_t* entry = file.data() + index_offset + kIndexEntryBytes * k;
    put_u32(entry, static_cast<std::uint32_t>(c->code_point));
    put_u32(entry + 4, static_cast<std::uint32_t>(offset));
    put_u32(entry + 8, crc32(record));
  }

  std::uint8_t* h = file.data();
  std::copy(kMagic.begin(), kMagic.end(), h);
  put_u16(h + kOffVersionMajor, kVersionMajor);
  put_u16(h + kOffVersionMinor, outlines          ? kVersionMinorWithOutlines
                                : options.medians ? kVersionMinor
                                                  : kVersionMinorWithoutMedians);
  put_u32(h + kOffHeaderSize, static_cast<std::uint32_t>(kHeaderBytes));
  put_u32(h + kOffCount, static_cast<std::uint32_t>(sorted.size()));
  put_u32(h + kOffSteps, static_cast<std::uint32_t>(steps));
  put_u32(h + kOffTolerance, float_bits(static_cast<float>(options.fit_tolerance)));
  put_u32(h + kOffFlags, (options.medians ? kFlagMedians : 0u) | (outlines ? kFlagOutlines : 0u));
  put_u64(h + kOffIndex, index_offset);
  put_u64(h + kOffRecords, records_offset);
  put_u64(h + kOffRecordsSize, file.size() - records_offset);
  for (std::size_t id = 1; id <= kTypicalStrokeCount; ++id) {
    const TypicalStroke& type = typical_stroke(static_cast<int>(id));
    put_u64(h + kHeaderBytes + 16 * (id - 1), double_bits(type.default_attraction));
    put_u64(h + kHeaderBytes + 16 * (id - 1) + 8, double_bits(type.corner_attraction));
  }
  put_u32(h + kOffTablesCrc, crc32(std::span(file).subspan(kHeaderBytes, records_offset - kHeaderBytes)));
  put_u32(h + kOffHeaderCrc, crc32(std::span(file).first(kOffHeaderCrc)));
  return file;
}

void write_corpus_store(const std::filesystem::path& path, std::span<const Character> characters,
                        const CorpusStoreOptions& options) {
  write_corpus_store(path, characters, options, {});
}

void write_corpus_store(const std::filesystem::path& path, std::span<const Character> characters,
                        const CorpusStoreOptions& options,
                        std::span<const std::vector<std::string>> outline_paths) {
  // Encoded whole before the file is touched, then written as every output is: an earlier store survives
  // any failure, and no temporary file is left behind.
  write_file_atomically(path, encode_corpus_store(characters, options, outline_paths));
}

}  // namespace calligraphy
