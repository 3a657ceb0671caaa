#pragma once
// What the simulated writer writes next (private to the sim module): its own order of the strokes (drawn
// at construction, with the profile's order and direction errors), one attempt at a time, the retries the
// display asks for (a refusal, a stroke cleared, a stroke not taken) and the give-up after
// max_attempts_per_stroke; with the plan of each attempt's path, and the log of what it did.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "sim/writer_error_injector.hpp"
#include "sim/writer_program.hpp"
#include "sim/writer_stroke_path.hpp"

namespace calligraphy::writer_detail {

/// What the writer means to write after an attempt ends.
enum class NextStroke {
  plan,  // the next stroke of its own plan (or, once refused, the one the display hints)
  hint,  // the stroke the display hints
  redo,  // the same stroke again
};

/// The attempt under way (or the last one).
struct OpenAttempt {
  PlannedStroke target;
  std::size_t log_index = 0;
  Polyline reference;             // the stroke as seen, in the writing direction [m]
  Vec2 start_m = Vec2::Zero();    // its start [m]
  bool mid_lift_reached = false;  // the pen has lifted in the middle of the stroke
  bool ended = true;
  std::size_t display_at_start = 0;  // the active stroke (scene index) the writer saw when it set off
  bool accepted = false;             // the writer has seen the display move past this stroke
};

/// The stroke chosen for the next attempt.
struct StrokeChoice {
  PlannedStroke target;
  bool follows_hint = false;  // the display hints it (after a refusal)
};

class WriterPlanner {
 public:
  /// Draws the writer's order of `scene`'s strokes from a stream seeded with `plan_seed` (per character:
  /// the copy's offset, the order, then each stroke's direction); the same stream then draws each attempt.
  /// `scene`, `profile` and `injector` must outlive the planner.
  WriterPlanner(const Scene& scene, const WriterProfile& profile, const WriterErrorInjector& injector,
                std::uint64_t plan_seed);

  [[nodiscard]] const std::vector<PlannedStroke>& plan() const noexcept { return plan_; }
  [[nodiscard]] const WriterLog& log() const noexcept { return log_; }
  [[nodiscard]] const OpenAttempt& attempt() const noexcept { return attempt_; }
  /// The writer has finished: its own plan written (a stroke given up on counts as written), or the
  /// display finished.
  [[nodiscard]] bool done() const noexcept { return done_; }
  /// Past its last attempt at a stroke the writer moved on (docs/writer.md, "Give-up and retries"): it
  /// writes the rest of its own plan and no longer waits for, or yields to, the display.
  [[nodiscard]] bool moved_on() const noexcept { return moved_on_; }

  /// What the writer last saw of the display: the active stroke and whether it finished. A display that
  /// moved past the stroke being written took it.
  void see_display(std::size_t character, std::size_t stroke, bool finished);
  /// The pen touched down to write the attempt's stroke at `time_s` [s] (the first time counts).
  void touched_down(double time_s);
  /// The pen lifted in the middle of the attempt's stroke.
  void reached_mid_lift();
  /// The hand wrote the attempt's whole path at `time_s` [s]: written, by the writer's own account.
  void complete_attempt(double time_s);
  /// The writer felt the display refuse the stroke.
  void count_refusal() noexcept { ++log_.refusals; }
  /// Ends the attempt under way at `time_s` [s] for `why`, then writes `then`. False when none was.
  bool break_off(double time_s, AttemptEnd why, NextStroke then);
  /// The hand's next program, once it has run out, from `hold_m` [m] at `time_s` [s]: a pause to see
  /// whether the display took the stroke, or the next attempt. Empty once done.
  [[nodiscard]] std::vector<Segment> next_program(double time_s, const Vec3& hold_m);

 private:
  [[nodiscard]] std::size_t seen_active() const;
  [[nodiscard]] PlannedStroke hinted() const;
  [[nodiscard]] int attempt_number(std::size_t scene_stroke) const;
  [[nodiscard]] bool earlier_stroke_open(const PlannedStroke& target) const;
  void end_attempt(double time_s, AttemptEnd why);
  void take_strokes_before_hint();
  [[nodiscard]] bool pause_for_verdict();
  [[nodiscard]] std::optional<StrokeChoice> choose_stroke() const;
  [[nodiscard]] std::vector<Segment> start_attempt(const PlannedStroke& target, bool follows_hint,
                                                   double time_s, const Vec3& hold_m);
  [[nodiscard]] std::vector<Segment> give_up(const PlannedStroke& target, double time_s, const Vec3& hold_m);
  void log_attempt(const PlannedStroke& target, int number, bool follows_hint, double time_s,
                   const AttemptErrors& errors);

  const Scene* scene_;
  const WriterProfile* profile_;
  const WriterErrorInjector* injector_;
  std::mt19937_64 rng_;
  std::vector<Vec2> character_offset_m_;
  std::vector<std::size_t> first_scene_stroke_;
  std::vector<PlannedStroke> plan_;
  std::vector<bool> written_;
  WriterLog log_;

  OpenAttempt attempt_;
  NextStroke next_ = NextStroke::plan;
  bool awaiting_verdict_ = false;  // pausing after a stroke to see whether the display took it
  PlannedStroke redo_target_;
  bool done_ = false;
  bool moved_on_ = false;

  // The display as last seen.
  std::size_t seen_character_ = 0;
  std::size_t seen_stroke_ = 0;
  bool seen_finished_ = false;
};

}  // namespace calligraphy::writer_detail
