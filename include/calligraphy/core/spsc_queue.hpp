#pragma once
/// \file spsc_queue.hpp
/// A bounded single-producer single-consumer lock-free queue of trivially copyable values: a ring of
/// slots allocated once, with the producer's and the consumer's positions in separate cache lines
/// (the classic Lamport ring, with acquire/release positions as in D. Vyukov's and Folly's
/// ProducerConsumerQueue). `try_push` and `try_pop` never wait, lock or allocate; a full queue refuses
/// the value (the producer counts it as dropped), it never blocks the producer.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

template <class T>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>, "SpscQueue holds trivially copyable values only");

 public:
  /// Room for at least `capacity` values (rounded up to a power of two), allocated here. Throws
  /// InvalidArgument when `capacity` is 0 or above 2^24.
  explicit SpscQueue(std::size_t capacity) {
    if (capacity == 0 || capacity > (std::size_t{1} << 24)) {
      throw InvalidArgument("SpscQueue capacity " + std::to_string(capacity) + " must be in [1, 16777216]");
    }
    std::size_t size = 1;
    while (size < capacity) size <<= 1;
    slots_ = std::make_unique<T[]>(size);
    mask_ = size - 1;
  }
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  /// Producer thread only. Appends `value`; false (nothing appended, the drop counted) when full.
  bool try_push(const T& value) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_.load(std::memory_order_acquire) > mask_) {
      dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return false;
    }
    slots_[tail & mask_] = value;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer thread only. Moves the oldest value into `out`; false when empty.
  bool try_pop(T& out) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    out = slots_[head & mask_];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Values in the queue now (exact from the producer or the consumer thread, approximate elsewhere).
  [[nodiscard]] std::size_t size() const noexcept {
    return tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }
  /// Values refused because the queue was full. Any thread.
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::unique_ptr<T[]> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};  // next slot to pop: written by the consumer
  alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to push: written by the producer
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace calligraphy
