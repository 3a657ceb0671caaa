#pragma once
// Internal: constants, CRC-32 and bit streams of the corpus store format (docs/corpus.md).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace calligraphy::store {

/// The largest file read as a store: its index addresses records at 32-bit offsets, so a longer file cannot
/// be a valid one (the whole corpus is a few megabytes).
inline constexpr std::size_t kMaxCorpusStoreBytes = std::size_t{1} << 32;

inline constexpr std::array<std::uint8_t, 8> kMagic = {'C', 'L', 'G', 'S', 'T', 'O', 'R', 'E'};
inline constexpr std::uint16_t kVersionMajor = 1;  // readers reject another major version
// Minor 0: the models only. Minor 1: header flag kFlagMedians may be set (the records then end with the
// strokes' medians). Minor 2: header flag kFlagOutlines may be set (the records then end with the strokes'
// outlines). Readers accept any minor and refuse flags they do not know.
inline constexpr std::uint16_t kVersionMinorWithOutlines = 2;
inline constexpr std::uint16_t kVersionMinor = 1;
inline constexpr std::uint16_t kVersionMinorWithoutMedians = 0;
inline constexpr std::size_t kHeaderBytes = 64;
inline constexpr std::size_t kTypicalStrokeCount = 39;
// Two float64 per typical ID: the default attraction factor, then the corner attraction factor.
inline constexpr std::size_t kDefaultsBytes = 16 * kTypicalStrokeCount;
inline constexpr std::size_t kIndexEntryBytes = 12;                    // code point, offset, CRC
inline constexpr std::int64_t kMaxCoordinate = std::int64_t{1} << 23;  // quantised |x|

// Header field offsets.
inline constexpr std::size_t kOffVersionMajor = 8, kOffVersionMinor = 10, kOffHeaderSize = 12, kOffCount = 16,
                             kOffSteps = 20, kOffTolerance = 24, kOffFlags = 28, kOffIndex = 32,
                             kOffRecords = 40, kOffRecordsSize = 48, kOffTablesCrc = 56, kOffHeaderCrc = 60;

// Header flags (u32 at kOffFlags).
inline constexpr std::uint32_t kFlagMedians = 1;  // every record ends with its strokes' medians (minor 1)
// Then with its strokes' outlines, where it has them (minor 2).
inline constexpr std::uint32_t kFlagOutlines = 2;
inline constexpr std::uint32_t kKnownFlags = kFlagMedians | kFlagOutlines;
// Outlines (SVG path data, one path per stroke): one bit, the character has them; then per stroke one bit,
// the path as text (1: a length of kOutlineTextLengthBits and the bytes) or compact (0): a command count in
// 7 bits (127: 16 bits follow), each command in 3 bits (kOutlineCommands), and the commands' points as whole
// data units, the first absolute, the others from the point before, x and y each in its own width.
inline constexpr char kOutlineCommands[] = {'M', 'L', 'Q', 'C', 'Z'};
inline constexpr int kOutlineCommandBits = 3;
inline constexpr std::uint64_t kOutlineCountEscape = 127;
inline constexpr int kOutlineCountBits = 7;
inline constexpr int kOutlineCountExtensionBits = 16;
inline constexpr int kOutlineTextLengthBits = 20;
/// Longest SVG path of one stroke's outline kept as text (length:20), bytes; the character-data readers
/// refuse a longer entry of `strokes`, so that every character a folder gives can be stored.
inline constexpr std::size_t kMaxOutlinePathBytes = (std::size_t{1} << kOutlineTextLengthBits) - 1;
/// Points a compact outline command takes (M, L, Q, C, Z).
inline constexpr int outline_command_points(char command) {
  return command == 'Q' ? 2 : command == 'C' ? 3 : command == 'Z' ? 0 : 1;
}
// Median points: a count of points per stroke in 5 bits; 31 means a 14-bit count follows.
inline constexpr std::uint64_t kMedianCountEscape = 31;
inline constexpr int kMedianCountExtensionBits = 14;
inline constexpr std::int64_t kMaxMedianCoordinate = std::int64_t{1} << 23;  // |x| in 2^-shift units
inline constexpr int kMaxMedianShift = 2;  // a median's coordinates in units of 2^-shift data units, 0-2
inline constexpr int kMedianRawMode = 3;   // else: each coordinate a float64 (data units, |x| <= 2^23)

// Per-stroke flags.
// Not every factor is the file's default for the ID: a 1-bit mode follows. Mode 1 (palette): one bit per
// feature point choosing the ID's default (0) or corner (1) factor. Mode 0: one float64 per feature point.
inline constexpr unsigned kExplicitFactors = 1;
inline constexpr unsigned kDetachedElements = 2;  // some element does not start where the previous ended

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib and PNG), slicing by one byte.
std::uint32_t crc32(std::span<const std::uint8_t> bytes);

inline std::uint32_t get_u32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}
inline std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
inline std::uint64_t get_u64(const std::uint8_t* p) {
  return get_u32(p) | std::uint64_t{get_u32(p + 4)} << 32;
}
inline float get_f32(const std::uint8_t* p) {
  const std::uint32_t bits = get_u32(p);
  float f = 0.0f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
inline void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_u64(std::uint8_t* p, std::uint64_t v) {
  put_u32(p, static_cast<std::uint32_t>(v));
  put_u32(p + 4, static_cast<std::uint32_t>(v >> 32));
}
inline std::uint64_t double_bits(double d) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &d, sizeof bits);
  return bits;
}
inline double get_f64(const std::uint8_t* p) {
  const std::uint64_t bits = get_u64(p);
  double d = 0.0;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}
inline std::uint32_t float_bits(float f) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

inline std::uint64_t zigzag(std::int64_t v) {
  return v >= 0 ? static_cast<std::uint64_t>(v) << 1 : (static_cast<std::uint64_t>(-(v + 1)) << 1) | 1u;
}
inline std::int64_t unzigzag(std::uint64_t u) {
  return (u & 1u) ? -static_cast<std::int64_t>(u >> 1) - 1 : static_cast<std::int64_t>(u >> 1);
}
/// Bits needed to hold u (0 for 0).
inline int bit_width(std::uint64_t u) {
  int n = 0;
  while (u != 0) {
    ++n;
    u >>= 1;
  }
  return n;
}

/// Appends bit fields, least significant bit first.
class BitWriter {
 public:
  void put(std::uint64_t value, int bits) {
    for (int i = 0; i < bits; ++i) {
      if (used_ == 0) bytes_.push_back(0);
      if ((value >> i) & 1u) bytes_.back() = static_cast<std::uint8_t>(bytes_.back() | (1u << used_));
      used_ = (used_ + 1) & 7;
    }
  }
  [[nodiscard]] std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
  int used_ = 0;
};

/// Reads bit fields; `get` returns false instead of reading past the end.
class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  [[nodiscard]] bool get(int bits, std::uint64_t& value) {
    if (bits < 0 || bits > 64 || static_cast<std::uint64_t>(bits) > remaining()) return false;
    value = 0;
    for (int got = 0; got < bits;) {  // whole bytes at a time
      const int offset = static_cast<int>(position_ & 7);
      const int take = std::min(8 - offset, bits - got);
      const std::uint64_t chunk = (bytes_[position_ >> 3] >> offset) & ((1u << take) - 1u);
      value |= chunk << got;
      got += take;
      position_ += static_cast<std::size_t>(take);
    }
    return true;
  }
  [[nodiscard]] std::uint64_t remaining() const { return bytes_.size() * 8 - position_; }
  [[nodiscard]] std::size_t bit_position() const { return position_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t position_ = 0;
};

}  // namespace calligraphy::store
