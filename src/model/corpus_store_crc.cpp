// CRC-32 of the corpus store: IEEE 802.3 polynomial, reflected (0xEDB88320), initial value and final
// XOR 0xFFFFFFFF, so it equals zlib's crc32() and `python3 -c "import zlib; zlib.crc32(...)"`.
#include <array>

#include "model/corpus_store_format.hpp"

namespace calligraphy::store {
namespace {

constexpr std::array<std::uint32_t, 256> make_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr auto kTable = make_table();

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::uint8_t b : bytes) c = kTable[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace calligraphy::store
