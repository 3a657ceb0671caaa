#pragma once
/// \file log_queue.hpp
/// Logging from a real-time thread without calling the logger there: the real-time thread pushes
/// fixed-size POD records into a lock-free single-producer/single-consumer ring buffer, and a normal
/// thread (`LogDrain`) pops them and hands them to a sink that formats and calls spdlog.
/// `try_push` never allocates, locks, blocks or throws; when the ring is full the new record is dropped
/// and counted (the producer must never wait for the consumer).
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <type_traits>

namespace calligraphy::devices {

/// A bounded lock-free queue for exactly one producer thread and one consumer thread.
/// `Capacity` is a power of two >= 2; `T` is trivially copyable (records are copied by value).
template <typename T, std::size_t Capacity>
class SpscQueue {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "Capacity must be a power of two");
  static_assert(std::is_trivially_copyable_v<T>, "records must be trivially copyable");

 public:
  /// Producer side. Copies `value` in and returns true, or returns false (and counts a drop) when full.
  bool try_push(const T& value) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == Capacity) {
      dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return false;
    }
    slots_[head & (Capacity - 1)] = value;
    head_.store(head + 1, std::memory_order_release);  // publishes the slot to the consumer
    return true;
  }

  /// Consumer side. Moves the oldest record into `out` and returns true, or returns false when empty.
  bool try_pop(T& out) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);  // hands the slot back to the producer
    return true;
  }

  /// Records dropped because the queue was full (any thread; written by the producer only).
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }
  /// Records waiting (any thread; a snapshot that may be stale by the time it is read).
  [[nodiscard]] std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  [[nodiscard]] static constexpr std::size_t capacity() noexcept { return Capacity; }

 private:
  // Producer and consumer indices on their own cache lines, so the two threads do not false-share.
  alignas(64) std::atomic<std::size_t> head_{0};  // next slot to write; written by the producer
  alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to read; written by the consumer
  alignas(64) std::atomic<std::uint64_t> dropped_{0};
  std::array<T, Capacity> slots_{};
};

enum class LogLevel : std::uint8_t { debug, info, warn, error };

/// One log record: a level, an event code the sink knows how to word, and numbers. A short text (e.g.
/// an exception's message) is copied into `text`, truncated, always NUL-terminated.
struct LogRecord {
  LogLevel level = LogLevel::info;
  std::uint16_t code = 0;
  std::int64_t time_ns = 0;        ///< CLOCK_MONOTONIC time stamp [ns]
  std::uint64_t count = 0;         ///< an event counter (e.g. tick number)
  std::array<double, 3> values{};  ///< numbers, units as the code defines
  std::array<char, 112> text{};

  /// Copies `message` into `text` (truncating); never allocates.
  void set_text(const char* message) noexcept;
};

using LogQueue = SpscQueue<LogRecord, 256>;

/// A normal thread that drains a `LogQueue` into a sink every `poll_interval`, and once more at `stop()`.
/// The sink runs on the drain thread and may allocate and call spdlog.
class LogDrain {
 public:
  using Sink = std::function<void(const LogRecord&)>;
  LogDrain() = default;
  ~LogDrain() { stop(); }
  LogDrain(const LogDrain&) = delete;
  LogDrain& operator=(const LogDrain&) = delete;

  /// Starts draining `queue` (not owned; must outlive the drain) into `sink`. No-op when already started.
  void start(LogQueue& queue, Sink sink,
             std::chrono::milliseconds poll_interval = std::chrono::milliseconds(20));
  /// Stops the thread after draining what is queued. Safe to call repeatedly; never throws.
  void stop() noexcept;
  /// Drains what is queued now, on the calling thread; returns the number of records handed to the sink.
  /// Only when the drain thread is not running (one consumer at a time).
  std::size_t drain_now();

 private:
  void run();
  LogQueue* queue_ = nullptr;
  Sink sink_;
  std::chrono::milliseconds poll_interval_{20};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace calligraphy::devices
