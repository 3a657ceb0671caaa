// CRC-32 of the corpus store: zlib's crc32() (IEEE 802.3 polynomial, reflected), so a store can be
// checked with `python3 -c "import zlib; zlib.crc32(...)"`.
#include <zlib.h>

#include <algorithm>
#include <limits>

#include "model/corpus_store_format.hpp"

namespace calligraphy::store {

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  // zlib takes a uInt length: feed stores larger than 4 GiB in chunks.
  uLong crc = ::crc32(0L, Z_NULL, 0);
  const std::uint8_t* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const auto chunk = static_cast<uInt>(std::min<std::size_t>(left, std::numeric_limits<uInt>::max()));
    crc = ::crc32(crc, data, chunk);
    data += chunk;
    left -= chunk;
  }
  return static_cast<std::uint32_t>(crc);
}

}  // namespace calligraphy::store
