#include "trainer/session_host.hpp"

namespace calligraphy::trainer {

using Clock = std::chrono::steady_clock;

WindowSessionHost::WindowSessionHost(const SessionManifest& manifest, bool unattended, double start_delay_s)
    : manifest_(manifest), unattended_(unattended), start_delay_s_(start_delay_s) {}

void WindowSessionHost::before_trial(const PlannedTrial& trial, std::size_t total) {
  std::unique_lock lock(mutex_);
  const StudyCondition& condition = manifest_.protocol.protocol.condition(trial.condition);
  view_.phase = SessionPhase::announced;
  ++view_.trial_generation;
  view_.trial = trial;
  view_.total = total;
  view_.mode = condition_mode(condition);
  view_.guidance = condition.guidance.has_value();
  view_.channel.reset();
  view_.outcome.reset();
  start_ = false;
  if (unattended_) {
    changed_.wait_for(lock, std::chrono::duration<double>(start_delay_s_), [this] { return stop_; });
  } else {
    changed_.wait(lock, [this] { return start_ || stop_; });
  }
}

void WindowSessionHost::rest(double seconds, const PlannedTrial& /*trial*/,
                             const std::function<bool()>& should_stop) {
  const auto until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::unique_lock lock(mutex_);
  view_.phase = SessionPhase::resting;
  view_.rest_until = until;
  // should_stop also reads the process's stop signals: polled, as no one notifies for those.
  while (Clock::now() < until && !stop_) {
    lock.unlock();
    const bool stop = should_stop();
    lock.lock();
    if (stop) break;
    changed_.wait_for(lock, std::chrono::milliseconds(50), [this] { return stop_; });
  }
}

void WindowSessionHost::after_trial(const PlannedTrial& /*trial*/, const TrialOutcome& outcome) {
  const std::lock_guard lock(mutex_);
  view_.phase = SessionPhase::outcome;
  view_.outcome = outcome;
}

DisplayChannel* WindowSessionHost::display_for(const PlannedTrial& /*trial*/,
                                               const StrokeAcceptance& acceptance) {
  auto channel = std::make_shared<DisplayChannel>();
  DisplayChannel* published = channel.get();
  const std::lock_guard lock(mutex_);
  view_.channel = std::move(channel);  // kept alive here and by the window's copies
  view_.acceptance = acceptance;
  view_.phase = SessionPhase::running;
  return published;
}

void WindowSessionHost::start_trial() {
  const std::lock_guard lock(mutex_);
  start_ = true;
  changed_.notify_all();
}

void WindowSessionHost::request_stop() {
  const std::lock_guard lock(mutex_);
  stop_ = true;
  changed_.notify_all();
}

bool WindowSessionHost::stop_requested() const {
  const std::lock_guard lock(mutex_);
  return stop_;
}

void WindowSessionHost::mark_finished() {
  const std::lock_guard lock(mutex_);
  view_.phase = SessionPhase::finished;
}

SessionView WindowSessionHost::view() const {
  const std::lock_guard lock(mutex_);
  return view_;
}

}  // namespace calligraphy::trainer
