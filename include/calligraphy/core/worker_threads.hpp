#pragma once
/// \file worker_threads.hpp
/// Worker threads that share one task's items, for a machine that may not give them (a limit on the threads
/// this user may run, RLIMIT_NPROC, or on memory): the work goes on with the threads that started.
#include <cstddef>
#include <functional>
#include <new>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace calligraphy {

/// Up to `count` threads each running `work`, joined by join() or the destructor (also when the caller's own
/// share of the work throws). A thread the system will not start (std::system_error: the threads this user
/// may run, RLIMIT_NPROC, or the memory of a thread's stack used up; std::bad_alloc: no memory for its
/// state) is not started and no error: the work is meant to take its items from a shared counter, so the
/// threads that did start, and the calling thread, do them all. started() says how many run; a caller that
/// does no share of the work itself runs `work` on its own thread when it is 0.
class WorkerThreads {
 public:
  WorkerThreads(std::size_t count, const std::function<void()>& work) {
    threads_.reserve(count);
    for (std::size_t t = 0; t < count; ++t) {
      try {
        threads_.emplace_back(work);
      } catch (const std::system_error&) {
        break;  // none more will start either
      } catch (const std::bad_alloc&) {
        // No memory for the thread's state (a copy of `work`): as a stack that cannot be mapped. Leaving the
        // constructor would destroy the threads already started unjoined, which ends the process.
        break;
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

/// Runs `task(i)` for every i in [0, count) on up to `threads` threads (0: one a hardware thread; never more
/// than `count`), the calling thread one of them; a thread the system will not start is done without, as
/// WorkerThreads. Items are taken in increasing order and each one taken runs to its end. Once an item has
/// thrown no further item starts, and when every thread has stopped the exception of the lowest-numbered item
/// that threw is rethrown: every item before it was taken and ran, so it is the error a run in turn would
/// meet first, whatever the threads. Returns the number of threads that ran (at least 1).
std::size_t for_each_item(std::size_t count, std::size_t threads,
                          const std::function<void(std::size_t)>& task);

}  // namespace calligraphy
