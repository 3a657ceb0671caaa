#pragma once
/// \file worker_threads.hpp
/// Worker threads that share one task's items, for a machine that may not give them (a limit on the threads
/// this user may run, RLIMIT_NPROC, or on memory): the work goes on with the threads that started.
#include <cstddef>
#include <functional>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace calligraphy {

/// Up to `count` threads each running `work`, joined by join() or the destructor (also when the caller's own
/// share of the work throws). A thread the system will not start (std::system_error: the threads this user
/// may run, RLIMIT_NPROC, or the memory of a thread's stack used up) is not started and no error: the work
/// is meant to take its items from a shared counter, so the threads that did start, and the calling thread,
/// do them all. started() says how many run; a caller that does no share of the work itself runs `work` on
/// its own thread when it is 0.
class WorkerThreads {
 public:
  WorkerThreads(std::size_t count, const std::function<void()>& work) {
    threads_.reserve(count);
    for (std::size_t t = 0; t < count; ++t) {
      try {
        threads_.emplace_back(work);
      } catch (const std::system_error&) {
        break;  // none more will start either
      }
    }
  }
  WorkerThreads(const WorkerThreads&) = delete;
  WorkerThreads& operator=(const WorkerThreads&) = delete;
  ~WorkerThreads() { join(); }

  [[nodiscard]] std::size_t started() const noexcept { return threads_.size(); }

  void join() noexcept {
    for (std::thread& thread : threads_) {
      if (thread.joinable()) thread.join();
    }
  }

 private:
  std::vector<std::thread> threads_;
};

}  // namespace calligraphy
