#include "trainer/trial_worker.hpp"

#include <utility>

namespace calligraphy::trainer {

TrialWorker::~TrialWorker() {
  if (thread_.joinable()) {
    request_stop();
    thread_.join();
  }
}

void TrialWorker::start(Scene scene, Checked<TrialSpec> spec, TrialRunInputs inputs) {
  if (thread_.joinable()) {
    request_stop();
    thread_.join();
  }
  scene_ = std::move(scene);
  spec_ = *spec;
  stop_.store(false);
  done_.store(false);
  result_.reset();
  failure_ = nullptr;
  writing_ = std::make_unique<SimulatedWriting>(*spec);
  inputs.hand_maker = writing_.get();
  inputs.should_stop = [this] { return stop_.load(std::memory_order_relaxed); };
  thread_ = std::thread([this, spec = std::move(spec), inputs = std::move(inputs)] {
    try {
      result_ = run_trial_spec(spec, scene_, inputs);
    } catch (...) {
      failure_ = std::current_exception();
    }
    done_.store(true, std::memory_order_release);
  });
}

TrialRun TrialWorker::take() {
  if (thread_.joinable()) thread_.join();
  if (failure_) {
    std::exception_ptr failure = failure_;
    failure_ = nullptr;
    std::rethrow_exception(failure);
  }
  TrialRun result = std::move(*result_);
  result_.reset();
  return result;
}

}  // namespace calligraphy::trainer
