#include "devices/log_queue.hpp"

#include <cstring>

namespace calligraphy::devices {

void LogRecord::set_text(const char* message) noexcept {
  text.fill('\0');
  if (message == nullptr) return;
  std::strncpy(text.data(), message, text.size() - 1);
}

void LogDrain::start(LogQueue& queue, Sink sink, std::chrono::milliseconds poll_interval) {
  if (thread_.joinable()) return;
  queue_ = &queue;
  sink_ = std::move(sink);
  poll_interval_ = poll_interval;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void LogDrain::stop() noexcept {
  if (!thread_.joinable()) return;
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

std::size_t LogDrain::drain_now() {
  if (queue_ == nullptr || !sink_) return 0;
  std::size_t n = 0;
  LogRecord record;
  while (queue_->try_pop(record)) {
    sink_(record);
    ++n;
  }
  return n;
}

void LogDrain::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, poll_interval_, [this] { return stopping_; });
    lock.unlock();
    try {
      drain_now();
    } catch (...) {  // a failing sink (e.g. a logger that cannot write) must not end the process
    }
    lock.lock();
  }
  lock.unlock();
  try {
    drain_now();  // what the producer pushed before it stopped
  } catch (...) {
  }
}

}  // namespace calligraphy::devices
