#pragma once
/// \file seqlock.hpp
/// A sequence lock over one trivially copyable value: one writer publishes without locking or waiting,
/// any number of readers copy the latest value and never see a torn one. The value is stored as 64-bit
/// atomic words, so no access is a data race (H.-J. Boehm, "Can seqlocks get along with programming
/// language memory models?", MSPC 2012: relaxed data accesses between a release fence on the writer's
/// side and an acquire fence on the reader's).
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <thread>
#include <type_traits>

namespace calligraphy {

template <class T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "Seqlock holds trivially copyable values only");
  static_assert(std::is_default_constructible_v<T>, "Seqlock values must be default constructible");

 public:
  static constexpr std::size_t kWords = (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);

  /// Holds `T{}` at version 0.
  Seqlock() noexcept {
    store(T{});
    sequence_.store(0, std::memory_order_relaxed);
  }
  Seqlock(const Seqlock&) = delete;
  Seqlock& operator=(const Seqlock&) = delete;

  /// Publishes `value`. One writer thread at a time (or writers ordered by other means, e.g. a join).
  /// Never waits, locks or allocates: a fixed number of relaxed atomic stores between two sequence
  /// updates.
  void store(const T& value) noexcept {
    std::array<std::uint64_t, kWords> words{};
    std::memcpy(words.data(), static_cast<const void*>(&value), sizeof(T));
    const std::uint64_t sequence = sequence_.load(std::memory_order_relaxed);
    sequence_.store(sequence + 1, std::memory_order_relaxed);  // odd: a write is in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(words[i], std::memory_order_relaxed);
    sequence_.store(sequence + 2, std::memory_order_release);
  }

  /// Copies the latest value into `out` and returns true, or returns false (leaving `out` as it was)
  /// when a write overlapped each of `attempts` tries. Any thread; never waits on the writer.
  bool try_load(T& out, int attempts = 4) const noexcept {
    std::array<std::uint64_t, kWords> words{};
    for (int attempt = 0; attempt < attempts; ++attempt) {
      const std::uint64_t before = sequence_.load(std::memory_order_acquire);
      if ((before & 1U) != 0) continue;
      for (std::size_t i = 0; i < kWords; ++i) words[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (sequence_.load(std::memory_order_relaxed) == before) {
        std::memcpy(static_cast<void*>(&out), words.data(), sizeof(T));  // T is trivially copyable
        return true;
      }
    }
    return false;
  }

  /// The latest value. Retries while a write is in progress, yielding the CPU after a few tries (the
  /// writer may have been preempted mid-write): lock-free, not wait-free. Prefer `try_load` on a thread
  /// that must never wait.
  [[nodiscard]] T load() const noexcept {
    T out{};
    while (!try_load(out, 16)) std::this_thread::yield();
    return out;
  }

  /// Values published so far. Any thread.
  [[nodiscard]] std::uint64_t version() const noexcept {
    return sequence_.load(std::memory_order_acquire) / 2;
  }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace calligraphy
