// The interposed malloc of allocation_count.hpp.
#include "allocation_count.hpp"

#include <cstddef>

namespace calligraphy::testing {
thread_local bool count_this_thread = false;
std::atomic<long> counted_allocations{0};
}  // namespace calligraphy::testing

#if !defined(CALLIGRAPHY_TEST_SANITIZED) && defined(__GLIBC__)
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (calligraphy::testing::count_this_thread) {
    calligraphy::testing::counted_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  return __libc_malloc(size);
}
#endif
