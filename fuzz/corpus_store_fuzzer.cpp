// libFuzzer target for the corpus store reader: any byte string either opens and loads, or throws
// DataError. Anything else (a crash, a sanitizer report, another exception) is a finding.
// Each input is read twice: as it is (exercising the checks of sizes and checksums) and with its
// checksums recomputed, so that mutations reach the index and record decoders behind the CRCs.
// Build and run: docs/corpus.md (Fuzzing).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "model/corpus_store_format.hpp"

namespace {

using namespace calligraphy::store;

// Recomputes whatever checksums the (possibly broken) layout lets us locate.
void fix_checksums(std::vector<std::uint8_t>& b) {
  if (b.size() < kHeaderBytes) return;
  const std::uint64_t count = get_u32(b.data() + kOffCount);
  const std::uint64_t index = kHeaderBytes + kDefaultsBytes;
  const std::uint64_t records = get_u64(b.data() + kOffRecords);
  if (records <= b.size() && records >= index && index + kIndexEntryBytes * count <= records) {
    const std::uint64_t records_size = b.size() - records;
    for (std::uint64_t k = 0; k < count; ++k) {
      std::uint8_t* entry = b.data() + index + kIndexEntryBytes * k;
      const std::uint64_t begin = get_u32(entry + 4);
      const std::uint64_t end = k + 1 < count ? get_u32(entry + kIndexEntryBytes + 4) : records_size;
      if (begin < end && end <= records_size) {
        put_u32(entry + 8, crc32(std::span(b.data() + records + begin, end - begin)));
      }
    }
    put_u32(b.data() + kOffTablesCrc, crc32(std::span(b.data() + kHeaderBytes, records - kHeaderBytes)));
  }
  put_u32(b.data() + kOffHeaderCrc, crc32(std::span(b.data(), kOffHeaderCrc)));
}

void read_all(std::span<const std::uint8_t> bytes) {
  try {
    const auto store = calligraphy::CorpusStore::from_bytes(bytes, "fuzz-input");
    std::size_t tried = 0;
    for (char32_t cp : store.characters()) {
      try {
        (void)store.load(cp);
        (void)store.load_outline_paths(cp);
      } catch (const calligraphy::DataError&) {
        // A bad record must not stop the others from being tried.
      }
      if (++tried > 4096) break;  // keep each input fast
    }
    (void)store.contains(U'永');
  } catch (const calligraphy::DataError&) {
    // The documented outcome for a bad file.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  read_all(std::span(data, size));
  std::vector<std::uint8_t> fixed(data, data + size);
  fix_checksums(fixed);
  read_all(fixed);
  return 0;
}
