#pragma once
// Counts the malloc calls of the threads that ask for it, for the tests of the servo path's promise (no
// allocation in a tick after the documented warm-up). malloc is interposed once for the test program that
// links allocation_count.cpp (calligraphy_study_tests) and forwards to glibc's __libc_malloc; operator new
// calls malloc. The sanitizers own malloc, so their builds leave it out: `kCountsAllocations` is false there
// and the counts stay 0.
#include <atomic>

namespace calligraphy::testing {

#if !defined(CALLIGRAPHY_TEST_SANITIZED) && defined(__GLIBC__)
inline constexpr bool kCountsAllocations = true;
#else
inline constexpr bool kCountsAllocations = false;
#endif

/// Set by a thread to have its own allocations counted (and cleared to stop).
extern thread_local bool count_this_thread;
/// The allocations of the counted threads so far.
extern std::atomic<long> counted_allocations;

}  // namespace calligraphy::testing
