#pragma once
// A study session hosted in the trainer's window (run_trainer_session): the session runs on its own
// thread, and this view follows its host once a frame: each planned trial as it is announced (its
// characters, scene and quiz), the trial's display channel drained into a TrialView, its outcome, and the
// panel's session section (the trial, the condition, what the person is asked to do).
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/trial/display.hpp"
#include "trainer/panel.hpp"
#include "trainer/quiz_log.hpp"
#include "trainer/session_host.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"

namespace calligraphy::trainer {

/// The study session a window hosts: the host, whether the session's thread is done, and its manifest.
struct SessionLink {
  WindowSessionHost* host = nullptr;
  const std::atomic<bool>* done = nullptr;
  const SessionManifest* manifest = nullptr;
};

class HostedSessionView {
 public:
  /// `link` and `characters` (every character of the plan) outlive the view. `unattended`: trials start
  /// by themselves, no key to press.
  HostedSessionView(const SessionLink& link, const std::vector<TrainerCharacter>& characters,
                    bool unattended);
  HostedSessionView(const HostedSessionView&) = delete;  // the trial view points into it
  HostedSessionView& operator=(const HostedSessionView&) = delete;

  /// Once a frame: the host's state. A trial announced since the last frame has `show_row` lay its
  /// characters out as the window's row (indices into `characters`) and gets a fresh view; the shown
  /// trial's display channel is drained into its view, its quiz verdicts and refusals logged, its outcome
  /// shown once it came.
  void follow(QuizLog& quiz_log, const std::function<void(const std::vector<std::size_t>&)>& show_row);
  /// The person asked to start the announced trial.
  void start_trial();
  /// Ends the session: the running trial is kept as an attempt.
  void request_stop();
  /// The session's thread is done.
  [[nodiscard]] bool finished() const;
  /// A trial runs: its snapshots are live.
  [[nodiscard]] bool trial_running() const noexcept { return state_.phase == SessionPhase::running; }
  /// The last planned trial's outcome came (the picture at the end is due).
  [[nodiscard]] bool last_trial_ended() const noexcept { return last_trial_ended_; }
  /// The trial shown, or null before the first.
  [[nodiscard]] const TrialView* view() const noexcept { return view_ ? &*view_ : nullptr; }
  /// The shown trial's scene, laid out as the session runner lays it out.
  [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
  /// The panel's session section: the trial's characters, the session line and the prompt.
  void fill_panel(PanelInput& panel) const;

 private:
  void show_trial(const SessionView& s, const std::function<void(const std::vector<std::size_t>&)>& show_row);
  [[nodiscard]] Scene trial_scene(const PlannedTrial& trial) const;

  const SessionLink& link_;
  const std::vector<TrainerCharacter>& characters_;
  std::map<char32_t, std::size_t> index_of_;  // a character's index in `characters_`
  bool unattended_ = false;
  SessionView state_;  // the host's, copied once a frame
  std::uint64_t shown_generation_ = 0;
  std::vector<std::string> shown_utf8_;  // the shown trial's characters
  std::vector<int> shown_typical_ids_;
  std::optional<TrialView> view_;
  std::shared_ptr<DisplayChannel> channel_;
  Scene scene_;
  bool last_trial_ended_ = false;
};

}  // namespace calligraphy::trainer
