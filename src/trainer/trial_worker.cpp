#include "trainer/trial_worker.hpp"

#include <utility>

namespace calligraphy::trainer {

TrialWorker::~TrialWorker() {
  if (thread_.joinable()) {
    request_stop();
    thread_.join();
  }
}

void TrialWorker::start(Scene scene, std::string device, TrialOptions options) {
  if (thread_.joinable()) {
    request_stop();
    thread_.join();
  }
  scene_ = std::move(scene);
  stop_.store(false);
  done_.store(false);
  result_.reset();
  failure_ = nullptr;
  options.should_stop = [this] { return stop_.load(std::memory_order_relaxed); };
  thread_ = std::thread([this, device = std::move(device), options = std::move(options)] {
    try {
      result_ = run_trial(device, scene_, options);
    } catch (...) {
      failure_ = std::current_exception();
    }
    done_.store(true, std::memory_order_release);
  });
}

TrialResult TrialWorker::take() {
  if (thread_.joinable()) thread_.join();
  if (failure_) {
    std::exception_ptr failure = failure_;
    failure_ = nullptr;
    std::rethrow_exception(failure);
  }
  TrialResult result = std::move(*result_);
  result_.reset();
  return result;
}

}  // namespace calligraphy::trainer
