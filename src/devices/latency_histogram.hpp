#pragma once
// A fixed-bin histogram of durations for one writer thread and any number of reader threads: every
// counter is a relaxed atomic, `add` never allocates or locks. 1000 fine bins of `fine_ns` cover
// [0, 1000 fine_ns), 990 coarse bins of 100 fine_ns cover the rest up to 100000 fine_ns, and one
// overflow bin takes everything beyond; the exact maximum and sum are kept beside the bins.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace calligraphy::devices {

class LatencyHistogram {
 public:
  static constexpr std::size_t kFineBins = 1000;
  static constexpr std::size_t kCoarseBins = 990;
  static constexpr std::size_t kBins = kFineBins + kCoarseBins + 1;  // + overflow

  explicit constexpr LatencyHistogram(std::int64_t fine_ns) noexcept : fine_ns_(fine_ns) {}

  /// Writer thread only. Negative durations count as 0.
  void add(std::int64_t ns) noexcept {
    ns = std::max<std::int64_t>(ns, 0);
    bump(bins_[bin_of(ns)], 1);
    bump(count_, 1);
    bump(sum_ns_, static_cast<std::uint64_t>(ns));
    if (static_cast<std::uint64_t>(ns) > max_ns_.load(std::memory_order_relaxed)) {
      max_ns_.store(static_cast<std::uint64_t>(ns), std::memory_order_relaxed);
    }
  }
  /// Writer thread only, while no reader relies on the contents.
  void clear() noexcept {
    for (auto& b : bins_) b.store(0, std::memory_order_relaxed);
    count_.store(0, std::memory_order_relaxed);
    sum_ns_.store(0, std::memory_order_relaxed);
    max_ns_.store(0, std::memory_order_relaxed);
  }

  [[nodiscard]] std::size_t bin_of(std::int64_t ns) const noexcept {
    const auto fine = static_cast<std::size_t>(ns / fine_ns_);
    if (fine < kFineBins) return fine;
    const std::size_t coarse = (fine - kFineBins) / 100;
    return coarse < kCoarseBins ? kFineBins + coarse : kBins - 1;
  }
  /// Upper edge of bin `i` [ns] (the overflow bin: the exact maximum).
  [[nodiscard]] std::int64_t upper_ns(std::size_t i) const noexcept {
    if (i < kFineBins) return static_cast<std::int64_t>(i + 1) * fine_ns_;
    if (i < kBins - 1)
      return (static_cast<std::int64_t>(kFineBins) + static_cast<std::int64_t>(i - kFineBins + 1) * 100) *
             fine_ns_;
    return static_cast<std::int64_t>(max_ns());
  }
  [[nodiscard]] std::uint64_t bin_count(std::size_t i) const noexcept {
    return bins_[i].load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t max_ns() const noexcept { return max_ns_.load(std::memory_order_relaxed); }
  [[nodiscard]] double mean_ns() const noexcept {
    const std::uint64_t n = count();
    return n == 0 ? 0.0
                  : static_cast<double>(sum_ns_.load(std::memory_order_relaxed)) / static_cast<double>(n);
  }
  /// The smallest bin upper edge below which at least `q` (in [0, 1]) of the samples lie [ns], capped at
  /// the maximum; 0 when empty. Any thread.
  [[nodiscard]] double quantile_ns(double q) const noexcept {
    std::uint64_t total = 0;
    for (const auto& b : bins_) total += b.load(std::memory_order_relaxed);
    if (total == 0) return 0.0;
    const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(total) + 0.5);
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += bins_[i].load(std::memory_order_relaxed);
      if (seen >= std::max<std::uint64_t>(rank, 1)) {
        return static_cast<double>(
            std::min<std::uint64_t>(static_cast<std::uint64_t>(upper_ns(i)), max_ns()));
      }
    }
    return static_cast<double>(max_ns());
  }

 private:
  // Single writer: a load and a store are enough (no read-modify-write bus lock on the servo path).
  static void bump(std::atomic<std::uint64_t>& a, std::uint64_t by) noexcept {
    a.store(a.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
  }
  std::int64_t fine_ns_;
  std::array<std::atomic<std::uint64_t>, kBins> bins_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> sum_ns_{0};
  std::atomic<std::uint64_t> max_ns_{0};
};

}  // namespace calligraphy::devices
