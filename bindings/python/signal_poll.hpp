#pragma once
// Ctrl-C during a long call that runs without the GIL (a trial, a cohort on C++ threads): Python runs its
// signal handlers only on the main thread, so the thread that made the call polls them, at most every 50 ms,
// and every other thread of the call reads the answer.
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>

namespace calligraphy::python {

class SignalPoll {
 public:
  // True once a signal handler has raised (a KeyboardInterrupt). Thread-safe: the calling thread takes the
  // GIL to run the handlers; any other thread only reads whether it did.
  bool interrupted() {
    if (interrupted_.load(std::memory_order_acquire)) return true;
    if (std::this_thread::get_id() != caller_) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(50)) return false;
    last_ = now;
    pybind11::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) {
      error_ = std::make_unique<pybind11::error_already_set>();  // keeps the exception until it is raised
      interrupted_.store(true, std::memory_order_release);
    }
    return interrupted_.load(std::memory_order_acquire);
  }
  // With the GIL held, on the calling thread: raises what a signal handler raised during the call.
  void raise_if_interrupted() {
    if (error_) throw std::move(*error_);
  }

 private:
  std::thread::id caller_ = std::this_thread::get_id();
  std::chrono::steady_clock::time_point last_ =
      std::chrono::steady_clock::now();  // the calling thread's alone
  std::atomic<bool> interrupted_{false};
  std::unique_ptr<pybind11::error_already_set> error_;  // written once, by the calling thread
};

}  // namespace calligraphy::python
