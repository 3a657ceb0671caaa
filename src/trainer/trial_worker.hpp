#pragma once
// One trial on its own thread: the trial specification's runner (run_trial_spec) with real-time pacing (the
// ServoLoop on yet another thread), stopped through TrialRunInputs::should_stop. The window thread starts it, polls `done()` once a frame
// and takes the result only once it is done, so it never waits on the servo side (except when quitting).
#include <atomic>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"

namespace calligraphy::trainer {

class TrialWorker {
 public:
  TrialWorker() = default;
  TrialWorker(const TrialWorker&) = delete;
  TrialWorker& operator=(const TrialWorker&) = delete;
  ~TrialWorker();

  /// Starts the trial `spec` of `scene` (kept here) with `inputs`, whose `should_stop` is replaced by this
  /// worker's stop flag and whose hand maker is the specification's simulated writer (made here: throws
  /// InvalidArgument for its profile).
  void start(Scene scene, Checked<TrialSpec> spec, TrialRunInputs inputs);
  [[nodiscard]] bool active() const noexcept { return thread_.joinable(); }
  /// True once the trial thread has finished (its result is ready).
  [[nodiscard]] bool done() const noexcept { return done_.load(std::memory_order_acquire); }
  /// Asks the trial to end (TrialEnd::interrupted, zero force, forces off, every tick kept).
  void request_stop() noexcept { stop_.store(true, std::memory_order_relaxed); }
  /// Joins the thread and returns what ran; rethrows what run_trial_spec threw.
  TrialRun take();
  [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
  /// The specification of the trial last started (recorded whole with its result).
  [[nodiscard]] const TrialSpec& spec() const noexcept { return spec_; }
  /// The simulated writer's profile of the trial last started (set before its thread, never changed by it).
  [[nodiscard]] const WriterProfile& writer_profile() const noexcept { return writing_->profile(); }

 private:
  Scene scene_;
  TrialSpec spec_;
  std::unique_ptr<SimulatedWriting> writing_;  // used by the trial thread while it runs
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  std::optional<TrialRun> result_;
  std::exception_ptr failure_;
};

}  // namespace calligraphy::trainer
