#pragma once
// The trainer window as a study session's host (study/session_runner.hpp): `run_session` runs on a thread
// of its own and tells this host what comes next; the window thread reads a copy of the state once a
// frame and never waits on the session thread. Before a trial the host waits for the person to start it
// (Space), or a moment when unattended; breaks count down; each trial gets a fresh display channel.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/trial/display.hpp"

namespace calligraphy::trainer {

enum class SessionPhase { waiting, announced, resting, running, outcome, finished };

/// What the window shows of the session: a copy, taken under the host's lock.
struct SessionView {
  SessionPhase phase = SessionPhase::waiting;
  std::uint64_t trial_generation = 0;  ///< counts before_trial calls: a new trial to show
  PlannedTrial trial;
  std::size_t total = 0;
  ConditionMode mode = ConditionMode::vision;  ///< the condition's spelling (condition_mode), for the panel
  bool guidance = false;
  std::shared_ptr<DisplayChannel> channel;  ///< the running (or last) trial's
  StrokeAcceptance acceptance;  ///< the running (or last) trial's, to judge pen-downs that never reach WS
  std::chrono::steady_clock::time_point rest_until;
  std::optional<TrialOutcome> outcome;
};

class WindowSessionHost final : public SessionHost {
 public:
  /// `manifest` outlives the host. `unattended`: trials start after `start_delay_s`, no key needed.
  WindowSessionHost(const SessionManifest& manifest, bool unattended, double start_delay_s);

  void before_trial(const PlannedTrial& trial, std::size_t total) override;
  void rest(double seconds, const PlannedTrial& trial, const std::function<bool()>& should_stop) override;
  void after_trial(const PlannedTrial& trial, const TrialOutcome& outcome) override;
  /// A new display channel for each trial, kept in the view with the acceptance its strokes are judged by.
  DisplayChannel* display_for(const PlannedTrial& trial, const StrokeAcceptance& acceptance) override;

  /// Window thread: the person asked to start the announced trial.
  void start_trial();
  /// Any thread: end the session (the running trial is kept as an attempt).
  void request_stop();
  [[nodiscard]] bool stop_requested() const;
  /// The session thread is done.
  void mark_finished();
  [[nodiscard]] SessionView view() const;

 private:
  const SessionManifest& manifest_;
  bool unattended_;
  double start_delay_s_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  SessionView view_;
  bool start_ = false;
  bool stop_ = false;
};

}  // namespace calligraphy::trainer
