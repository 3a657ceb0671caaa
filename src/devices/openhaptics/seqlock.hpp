#pragma once
// Single-writer sequence lock over a few doubles: the OpenHaptics scheduler thread publishes and the
// servo thread reads without locks or allocation. Every field is an atomic, so there is no data race.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace calligraphy::openhaptics {

template <std::size_t N>
class SeqLocked {
 public:
  /// One writer thread only.
  void store(const std::array<double, N>& values) noexcept {
    const std::uint32_t sequence = sequence_.load(std::memory_order_relaxed);
    sequence_.store(sequence + 1, std::memory_order_relaxed);  // odd: write in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < N; ++i) values_[i].store(values[i], std::memory_order_relaxed);
    sequence_.store(sequence + 2, std::memory_order_release);
  }
  /// Any thread; retries while a write is in progress, so the result is never torn.
  [[nodiscard]] std::array<double, N> load() const noexcept {
    std::array<double, N> out{};
    for (;;) {
      const std::uint32_t before = sequence_.load(std::memory_order_acquire);
      if ((before & 1U) != 0) continue;
      for (std::size_t i = 0; i < N; ++i) out[i] = values_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (sequence_.load(std::memory_order_relaxed) == before) return out;
    }
  }

 private:
  std::atomic<std::uint32_t> sequence_{0};
  std::array<std::atomic<double>, N> values_{};
};

}  // namespace calligraphy::openhaptics
