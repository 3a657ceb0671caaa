#pragma once
// Sample counts for the sanitizer builds. AddressSanitizer and ThreadSanitizer run this suite 10-30 times
// slower than Release; a test that sweeps a corpus, many rates or many seeds runs there on a random subset
// of the same sweep: the same property on fewer samples, never a fixed (possibly easy) subset. The subset
// is drawn from a seed printed to the test's output; CALLIGRAPHY_TEST_SEED=N repeats a draw. Release builds
// run every sample, and so does a sanitizer build with CALLIGRAPHY_TEST_FULL=1. docs/testing.md lists the
// tests that run smaller under the sanitizers.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace calligraphy::testing {

#if defined(CALLIGRAPHY_TEST_SANITIZED)  // tests/CMakeLists.txt
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif

/// The seed of this process's random subsets: CALLIGRAPHY_TEST_SEED when set, else drawn from the clock;
/// printed once.
inline std::uint64_t subset_seed() {
  static const std::uint64_t seed = [] {
    const char* text = std::getenv("CALLIGRAPHY_TEST_SEED");
    const std::uint64_t value =
        text != nullptr && *text != '\0'
            ? std::strtoull(text, nullptr, 10)
            : static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    std::cout << "sanitizer build: random subsets drawn with CALLIGRAPHY_TEST_SEED=" << value << "\n";
    return value;
  }();
  return seed;
}

/// True when this build runs the full sweeps: a Release build, or any build with CALLIGRAPHY_TEST_FULL=1.
inline bool full_sweeps() {
  const char* text = std::getenv("CALLIGRAPHY_TEST_FULL");
  return !kSanitizedBuild || (text != nullptr && std::string(text) == "1");
}

/// Every element when `full_sweeps()`; in a sanitizer build `sanitized_count` of them (all when there are no
/// more), drawn at random with `subset_seed()` mixed with `salt` (so that two sweeps of one test draw
/// independently) and kept in their original order. `what` names the sweep in the printed line.
template <class T>
std::vector<T> sanitizer_subset(const std::vector<T>& all, std::size_t sanitized_count,
                                const std::string& what, std::uint64_t salt = 0) {
  if (full_sweeps() || sanitized_count >= all.size()) return all;
  std::vector<std::size_t> order(all.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::mt19937_64 random(subset_seed() ^ (salt * 0x9e3779b97f4a7c15ULL));
  std::shuffle(order.begin(), order.end(), random);
  order.resize(sanitized_count);
  std::sort(order.begin(), order.end());
  std::vector<T> subset;
  std::cout << what << ": " << sanitized_count << " of " << all.size() << " samples under the sanitizer:";
  for (const std::size_t i : order) {
    subset.push_back(all[i]);
    std::cout << ' ' << i;
  }
  std::cout << "\n";
  return subset;
}

}  // namespace calligraphy::testing
