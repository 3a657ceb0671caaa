#include "calligraphy/core/worker_threads.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>

namespace calligraphy {

std::size_t for_each_item(std::size_t count, std::size_t threads,
                          const std::function<void(std::size_t)>& task) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = std::clamp<std::size_t>(threads, 1, std::max<std::size_t>(1, count));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  std::size_t failed_item = 0;
  const auto work = [&] {
    // An exception leaving a worker would end the process: each is kept, the lowest item's.
    for (std::size_t i = next++; i < count && !failed; i = next++) {
      try {
        task(i);
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure || i < failed_item) {
          failure = std::current_exception();
          failed_item = i;
        }
        failed = true;
      }
    }
  };
  WorkerThreads pool(threads - 1, work);
  work();
  pool.join();
  if (failure) std::rethrow_exception(failure);
  return pool.started() + 1;
}

}  // namespace calligraphy
