// The practice of `calligraphy train` (practice_controller.hpp): a trial started, followed once a frame,
// its result taken, saved and summarised, and the guidance of the next one.
#include "trainer/practice_controller.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/render/guidance_schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "trainer/stop_reason.hpp"

namespace calligraphy::trainer {

PracticeController::PracticeController(const TrainerOptions& options, DeviceInfo device_info, bool hardware)
    : options_(options), device_info_(std::move(device_info)), hardware_(hardware) {
  for (const TrainerCharacter& c : options.characters) typical_ids_.push_back(typical_ids_of(c.model));
  guidance_ = options.guidance && !options.quiz;  // a quiz is force-free but for the paper
  // The quiz judges with the renderer's tolerances and start neighbourhood: those of the trials start_trial
  // runs (the options' acceptance, a default scene layout), also in the practice protocol saved first.
  quiz_options_ = options.quiz_options;
  quiz_options_.acceptance = options.acceptance;
  quiz_options_.start_radius_m = SceneLayout{}.start_radius_m;
  guidance_mode_ = options.guidance_mode;
  guidance_gain_ = options.guidance_gain;
  condition_outputs_force_ = options.device != "mouse";
  demonstrated_.assign(options.characters.size(), false);
}

void PracticeController::open_practice_folder() {
  if (options_.session_dir.empty()) return;
  PracticeSetup setup;
  setup.root = options_.session_dir;
  setup.subject = options_.subject;
  for (const TrainerCharacter& c : options_.characters) setup.characters_utf8 += c.utf8;
  setup.first_condition = condition_name();
  setup.device = options_.device;
  setup.device_info = device_info_;
  setup.hardware = hardware_;
  setup.simulated_writer = options_.simulated_writer;
  setup.writer_profile = options_.writer_profile;
  setup.writer_seed = options_.seed;
  setup.quiz = quiz_options_;
  practice_folder_.emplace(setup);
  std::fprintf(stderr, "calligraphy train: saving into %s\n", practice_folder_->path().c_str());
}

// The condition of the next trial, as the session folder names it.
std::string PracticeController::condition_name() const {
  if (options_.quiz) return kQuizCondition;
  if (!guidance_ || !condition_outputs_force_) return kVisionCondition;
  switch (guidance_mode_) {
    case GuidanceMode::fading:
      return kFadingCondition;
    case GuidanceMode::replay:
      return kReplayCondition;
    case GuidanceMode::assist_as_needed:
      return kAssistCondition;
    case GuidanceMode::error_amplification:
      return kAmplificationCondition;
    case GuidanceMode::timing:
      return kTimingCondition;
    case GuidanceMode::fixed:
      break;
  }
  return kHapticCondition;
}

void PracticeController::start_trial(std::size_t character) {
  // Shown once per character before its first trial, to a person who writes it (not a quiz, which asks
  // what is remembered, nor the simulated writer, nor an unattended run).
  const bool first_look = options_.demonstrate && !unattended() && !options_.quiz &&
                          !options_.simulated_writer && !demonstrated_[character];
  if (first_look) {
    begin_demonstration(character);
  } else {
    launch_trial(character);
  }
}

void PracticeController::begin_demonstration(std::size_t character) {
  std::vector<Character> one{options_.characters[character].model};
  Demonstration demo;
  demo.character = character;
  demo.scene = Scene::lay_out(one);  // as start_trial lays the trial out: the same median on the paper
  std::vector<double> lengths_m;
  for (const PlacedStroke& stroke : demo.scene.characters.front().strokes)
    lengths_m.push_back(stroke.median_m.size() > 1 ? polyline_length(stroke.median_m) : stroke.length_m());
  demo.schedule = DemoSchedule(std::move(lengths_m), DemoPace{});
  demo.started = Clock::now();
  std::fprintf(stderr, "calligraphy train: demonstrating the stroke order of %s (%zu stroke%s, %.1f s)\n",
               options_.characters[character].utf8.c_str(), demo.schedule.strokes(),
               demo.schedule.strokes() == 1 ? "" : "s", demo.schedule.duration_s());
  demo_ = std::move(demo);
  demonstrated_[character] = true;
  advance_at_.reset();
}

void PracticeController::demonstrate() {
  if (demo_) {  // again during one: the rest is skipped, and the trial starts
    demo_->started = Clock::now() - std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(demo_->schedule.duration_s() + 1.0));
    return;
  }
  pending_ = NextAction::demonstrate;
}

std::optional<DemoView> PracticeController::demo_view() const {
  if (!demo_) return std::nullopt;
  DemoView view;
  view.box = demo_->character;
  view.placed = &demo_->scene.characters.front();
  view.frame = demo_->schedule.at(std::chrono::duration<double>(Clock::now() - demo_->started).count());
  view.strokes = demo_->schedule.strokes();
  return view;
}

void PracticeController::launch_trial(std::size_t character) {
  std::vector<Character> one{options_.characters[character].model};
  Scene scene = Scene::lay_out(one);  // at the device's centre; the row shows it at its place
  channel_ = std::make_unique<DisplayChannel>();
  view_.emplace();
  view_->character = character;
  view_->number = ++trials_started_;
  stop_cause_.clear();
  view_->guidance = guidance_;
  view_->condition = condition_name();
  // The trial specification of this trial; the teacher (read once, as samples), the display channel and what
  // a window process needs are the runner's inputs.
  TrialSpec spec;
  spec.characters = options_.characters[character].utf8;
  spec.device = options_.device;
  spec.guidance = guidance_;
  if (guidance_) spec.guidance_mode = guidance_mode_;
  if (spec.guidance_mode == GuidanceMode::fading) spec.guidance_gain = guidance_gain_;
  if (spec.guidance_mode == GuidanceMode::assist_as_needed) spec.assist_band_m = assist_band_m_;
  spec.writer = options_.simulated_writer ? TrialWriter::simulated : TrialWriter::person;
  if (options_.simulated_writer) spec.writer_profile = options_.writer_profile;
  spec.seed = options_.seed + trials_started_ - 1;
  spec.pacing = TrialPacing::real_time;
  spec.watchdog_s = options_.watchdog_s.value_or(default_watchdog_s(hardware_));
  spec.acceptance = options_.acceptance;  // the hint and the assisted credit after the options' misses
  TrialRunInputs inputs;
  inputs.registry = options_.registry;
  inputs.teacher = options_.teacher;
  inputs.display = channel_.get();
  inputs.lock_memory = false;  // a window process (TrialRunInputs::lock_memory)
  // Checked once, here; the runner and the renderer take it as it is.
  auto checked = Checked<TrialSpec>::check(
      std::move(spec), inputs.teacher.empty() ? TeacherSource::file : TeacherSource::samples);
  trial_options_ = trial_options(checked, DeviceInfo{});  // what the view needs before the device is open
  trial_simulation_.seed = checked->seed;
  trial_start_utc_ = utc_now_iso8601();
  trial_wall_start_ = Clock::now();
  worker_.start(std::move(scene), std::move(checked), std::move(inputs));
  trial_simulation_.writer = worker_.writer_profile();  // the profile the worker's writer checked and writes
  view_->scene = &worker_.scene();
  view_->acceptance = trial_options_.force.acceptance;
  // The quiz and the renderer judge a stroke alike (the live quiz, and the saved record's quiz through the
  // practice protocol: the same values, set when the controller was made).
  quiz_options_.acceptance = trial_options_.force.acceptance;
  quiz_options_.start_radius_m = worker_.scene().layout.start_radius_m;
  if (options_.quiz) view_->quiz.emplace(worker_.scene(), quiz_options_);
  advance_at_.reset();
}

void PracticeController::follow_trial(bool quitting, QuizLog& quiz_log) {
  if (quitting && worker_.active() && !worker_.done()) worker_.request_stop();
  if (pending_ != NextAction::none && worker_.active() && !worker_.done()) {
    note_stop_cause(pending_ == NextAction::repeat        ? "R (repeat)"
                    : pending_ == NextAction::demonstrate ? "D (demonstration)"
                                                          : "N (next character)");
    worker_.request_stop();
  }
  if (view_ && worker_.active()) {
    view_->consume(*channel_, typical_ids_[view_->character]);
    quiz_log.log_verdicts(*view_, characters_utf8(*view_));
    quiz_log.log_refusal(*view_, characters_utf8(*view_));
    // The quiz asks for every stroke in order, judged its own way: once each is accepted the trial has
    // done its job and ends (saved as completed, see finish_trial), whatever the renderer counted.
    if (view_->quiz && view_->quiz->complete() && !worker_.done()) worker_.request_stop();
  }
  if (worker_.active() && worker_.done()) finish_trial(quiz_log);
}

void PracticeController::start_next_trial() {
  if (demo_) {  // the trial waits for the demonstration's end; N meanwhile goes on to the next character
    if (demo_view()->frame.done) {
      const std::size_t character = demo_->character;
      const bool next = pending_ == NextAction::next;
      demo_.reset();
      pending_ = NextAction::none;
      if (next) {
        start_trial((character + 1) % options_.characters.size());
      } else {
        launch_trial(character);
      }
    }
    return;
  }
  if (pending_ == NextAction::demonstrate) {
    pending_ = NextAction::none;
    begin_demonstration(view_ ? view_->character : 0);
    return;
  }
  if (pending_ == NextAction::repeat) start_trial(view_->character);
  if (pending_ == NextAction::next) start_trial((view_->character + 1) % options_.characters.size());
  pending_ = NextAction::none;
  if (advance_at_ && Clock::now() >= *advance_at_) start_trial(view_->character + 1);
}

void PracticeController::stop_trial() {
  if (worker_.active() && !worker_.done()) worker_.request_stop();
}

void PracticeController::finish_trial(QuizLog& quiz_log) {
  TrialView& view = *view_;
  TrialRun run;
  try {
    run = worker_.take();
  } catch (const std::exception& e) {
    view.have_result = true;
    view.ended = true;
    view.end = TrialEnd::device_fault;
    view.end_reason = e.what();
    std::fprintf(stderr, "calligraphy train: the trial could not run: %s\n", e.what());
    failed_ = true;
    close_window_ = true;  // nothing to retry with the same device
    log_stop("device_fault");
    return;
  }
  trial_options_ = run.options;  // what the trial ran with (the stiffness fitted to the device)
  TrialResult& result = run.result;
  view.consume(*channel_, typical_ids_[view.character]);
  quiz_log.log_verdicts(view, characters_utf8(view));
  quiz_log.log_refusal(view, characters_utf8(view));
  if (view.quiz)
    check_quiz_against_trace(*view.quiz, worker_.scene(), result.trace, quiz_options_,
                             practice_folder_.has_value());
  if (view.quiz && view.quiz->complete() && result.end == TrialEnd::interrupted) {
    // Stopped once the quiz was complete (by the loop, or a key in the same moment): the quiz's task is
    // done, so the trial is complete, and saved as a trial rather than an attempt.
    result.end = TrialEnd::completed;
    result.aborted = false;
    result.abort_reason.clear();
  }
  if (result.end == TrialEnd::interrupted && result.abort_reason.empty() && !stop_reason().empty())
    result.abort_reason = "stopped by " + stop_reason();  // a lost display or a stop signal
  view.have_result = true;
  view.ended = true;
  view.end = result.end;
  // What the panel and the log report of the writing is the one metrics record (as a session record and
  // `calligraphy score` would give it); the renderer's counts stay as they were.
  const WritingMetrics& writing = run.metrics;
  view.metrics = result.metrics;
  view.metrics.mean_deviation_m =
      writing.deviation ? std::optional<double>(writing.deviation->mean_m) : std::nullopt;
  view.metrics.max_deviation_m =
      writing.deviation ? std::optional<double>(writing.deviation->max_m) : std::nullopt;
  view.metrics.time_s = writing.total_time_s.value_or(0.0);
  view.end_reason = result.abort_reason;
  if (result.end == TrialEnd::device_fault || result.end == TrialEnd::watchdog) failed_ = true;
  adapt_guidance(view);
  // A teacher's recording must write every stroke as the renderer reads it (replay follows it stroke by
  // stroke); a completed quiz need not have.
  if (!options_.record.empty() && result.end == TrialEnd::completed &&
      result.metrics.strokes_completed == result.metrics.strokes_total)
    save_recording(view, result);
  const std::string saved = practice_folder_ ? save_trial(view, result) : std::string();
  std::fprintf(stderr, "calligraphy train: %s\n", trial_summary(view, result, writing, saved).c_str());
  if (result.loop) {
    const ServoLoopStats& loop = *result.loop;
    std::fprintf(stderr,
                 "calligraphy train: servo loop: %llu ticks, %llu late, %llu forces withheld, period jitter "
                 "p50 %.1f us, p99 %.1f us, max %.1f us, longest stall %.2f ms\n",
                 static_cast<unsigned long long>(loop.ticks),
                 static_cast<unsigned long long>(loop.late_ticks),
                 static_cast<unsigned long long>(loop.forces_withheld), loop.period_jitter_us_p50,
                 loop.period_jitter_us_p99, loop.period_jitter_us_max, loop.longest_stall_s * 1e3);
  }
  if (result.end == TrialEnd::device_fault) {  // the device is lost: no further trial can run on it
    std::fprintf(stderr, "calligraphy train: error: the device failed (%s); the window closes\n",
                 result.abort_reason.c_str());
    close_window_ = true;
    log_stop("device_fault");
  }
  const bool last = view.character + 1 == options_.characters.size();
  if (last) last_character_ended_ = true;  // after the last character's last stroke
  // A key's request (D, R, N) comes first: the run goes on with the trial it asked for.
  if (unattended() && pending_ == NextAction::none) {
    if (last) {
      close_window_ = true;
    } else {
      advance_at_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(kAdvanceDelayS));
    }
  }
}

// The next trial's gain or band from this one's outcome, by the one schedule the studies use
// (render/guidance_schedule.hpp): a trial that wrote no stroke brings full guidance back.
void PracticeController::adapt_guidance(const TrialView& view) {
  const GuidanceMode mode = mode_of(trial_options_.force.guidance_law);
  if (!guidance_ || (mode != GuidanceMode::fading && mode != GuidanceMode::assist_as_needed)) return;
  GuidanceSchedule schedule;
  schedule.adapts =
      mode == GuidanceMode::fading ? AdaptiveGuidance::fading : AdaptiveGuidance::assist_as_needed;
  RepetitionGuidance now;
  now.mode = mode;
  now.gain = guidance_gain_;
  now.band_m = assist_band_m_;
  const RepetitionGuidance next = schedule.next(now, view.metrics.mean_deviation_m);
  guidance_gain_ = next.gain;
  assist_band_m_ = next.band_m;
  if (schedule.adapts == AdaptiveGuidance::fading) {
    std::fprintf(stderr, "calligraphy train: fading: next trial's guidance gain %.3f\n", guidance_gain_);
  } else {
    std::fprintf(stderr, "calligraphy train: assist-as-needed: next trial's band %.2f mm\n",
                 assist_band_m_ * 1e3);
  }
}

// One line a person reads of the trial that ended: how it ended and why, what the pen wrote (no deviation
// of strokes never written), and what was kept of it.
std::string PracticeController::trial_summary(const TrialView& view, const TrialResult& result,
                                              const WritingMetrics& writing, const std::string& saved) const {
  std::string line = "trial " + std::to_string(view.number) + " " + options_.characters[view.character].utf8 +
                     ": " + to_string(result.end);
  if (result.end == TrialEnd::interrupted) {
    const std::string stopped_by = "stopped by ";
    if (result.abort_reason.rfind(stopped_by, 0) == 0) {
      line += " by " + result.abort_reason.substr(stopped_by.size());
    } else if (!stop_cause_.empty()) {
      line += " by " + stop_cause_;
    }
  } else if (result.end != TrialEnd::completed && !result.abort_reason.empty()) {
    line += " (" + result.abort_reason + ")";
  }
  char text[160];
  std::snprintf(text, sizeof text, " after %.1f s; ", result.metrics.time_s);
  line += text;
  const std::size_t total = result.metrics.strokes_total;
  if (writing.strokes_written == 0 && result.metrics.strokes_completed == 0) {
    line += "no stroke written";
  } else {
    line += std::to_string(result.metrics.strokes_completed) + " of " + count_of(total, "stroke", "strokes") +
            " accepted in order";
    if (writing.deviation) {
      std::snprintf(text, sizeof text, ", mean deviation %.2f mm over %zu written",
                    writing.deviation->mean_m * 1e3, writing.strokes_written);
      line += text;
    }
  }
  if (!saved.empty()) {  // the session folder keeps a trial that did not end well as an attempt
    line += view.saved_as.rfind("attempts/", 0) == 0 ? "; kept as an attempt: " : "; saved as ";
    line += saved;
  } else if (!view.save_error.empty()) {
    line += "; " + view.save_error;
  } else {
    line += "; not saved (no --session)";
  }
  return line;
}

// The trial into the practice folder: as a trial, or as an attempt when it did not complete. Returns the
// record's path, or "" when it could not be saved (view.save_error says why).
std::string PracticeController::save_trial(TrialView& view, const TrialResult& result) {
  PracticeTrial trial;
  trial.item = view.character;
  trial.character = options_.characters[view.character].model.code_point;
  trial.condition = view.condition;
  trial.scene = &worker_.scene();
  trial.options = &trial_options_;
  trial.spec = &worker_.spec();
  trial.simulation = trial_simulation_;
  trial.start_utc = trial_start_utc_;
  trial.end_utc = utc_now_iso8601();
  trial.wall_time_s = std::chrono::duration<double>(Clock::now() - trial_wall_start_).count();
  try {
    const auto [path, as_trial] = practice_folder_->save(trial, result);
    view.saved_as = (as_trial ? "" : "attempts/") + path.filename().string();
    return path.string();
  } catch (const std::exception& e) {
    view.save_error = std::string("not saved: ") + e.what();
    std::fprintf(stderr, "calligraphy train: error: the trial was not saved: %s\n", e.what());
    failed_ = true;
  }
  return {};
}

// A lost display, a stop signal, a lost device: logged once.
void PracticeController::log_stop(const std::string& reason) {
  if (!practice_folder_ || stop_logged_) return;
  stop_logged_ = true;
  try {
    practice_folder_->log_stop(reason);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "calligraphy train: error: the session's log: %s\n", e.what());
    failed_ = true;
  }
}

// The last completed trial as a teacher's recording (replay guidance), replaced atomically.
void PracticeController::save_recording(TrialView& view, const TrialResult& result) {
  try {
    const TeacherRecording recording =
        teacher_recording_from_trace(options_.characters[view.character].utf8,
                                     options_.simulated_writer ? options_.writer_profile : "person",
                                     options_.device, trial_options_.rate_hz, result.trace);
    write_file_atomically(options_.record, teacher_recording_json(recording));
    std::fprintf(stderr, "calligraphy train: teacher recording %s (%zu samples)\n", options_.record.c_str(),
                 recording.samples.size());
  } catch (const std::exception& e) {
    view.save_error += std::string(" recording not written: ") + e.what();
    std::fprintf(stderr, "calligraphy train: error: the recording was not written: %s\n", e.what());
    failed_ = true;
  }
}

void PracticeController::toggle_guidance() noexcept {
  if (!options_.quiz) guidance_ = !guidance_;  // a quiz has no guidance
}

// The guidance mode of the next trial, in turn (replay only with a teacher).
void PracticeController::next_guidance_mode() {
  if (options_.quiz) return;
  const std::span<const GuidanceMode> modes = guidance_modes();
  auto at = std::find(modes.begin(), modes.end(), guidance_mode_);
  do {
    at = std::next(at) == modes.end() ? modes.begin() : std::next(at);
  } while (*at == GuidanceMode::replay && options_.teacher.empty());
  guidance_mode_ = *at;
}

std::span<const std::string> PracticeController::characters_utf8(const TrialView& view) const {
  return {&options_.characters[view.character].utf8, 1};  // a practice trial's scene: its one character
}

void PracticeController::fill_panel(PanelInput& panel) const {
  if (view_) {
    panel.character = options_.characters[view_->character].utf8;
    panel.outlined = options_.characters[view_->character].outlined();
  }
  panel.next_guidance = guidance_;
  panel.next_mode = to_string(guidance_mode_);
  panel.next_gain = guidance_gain_;
}

}  // namespace calligraphy::trainer
