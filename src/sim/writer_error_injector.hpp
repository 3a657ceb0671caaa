#pragma once
// The simulated writer's deliberate errors (private to the sim module), at the rates its profile sets:
// strokes swapped in its own order, strokes meant backwards, and per attempt a touch outside the
// character's box, a hesitation and a lift in the middle of the stroke; with the bias of its copy (an
// offset per character, a jitter per attempt). The errors are drawn from the plan's stream, each with a
// fixed number of draws in a fixed order, and shaped here into the segments of an attempt's program.
#include <cstddef>
#include <random>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "sim/writer_program.hpp"

namespace calligraphy::writer_detail {

/// The errors of one attempt, drawn as it starts.
struct AttemptErrors {
  bool outside_touch = false;  // the pen touches the paper outside the character's box first
  bool hesitate = false;       // a pause before the stroke or at a corner
  double hesitation_where =
      0.0;                    // in [0, 1): before the stroke (< 0.5, or a stroke of one leg), else the corner
  double hesitation_s = 0.0;  // how long the pause lasts [s]
  bool mid_stroke_lift = false;  // the pen is lifted in the middle of a leg
  double lift_where = 0.0;       // in [0, 1): which leg
  double lift_fraction = 0.0;    // in [0.3, 0.7): how far along the leg (of its arc up to the seen end)
  Vec2 jitter_m = Vec2::Zero();  // this attempt's shift of the whole copy [m]
};

/// Where a hesitation goes among the legs of a stroke.
struct HesitationPlace {
  bool before_stroke = false;  // above the start, before the descent
  std::size_t after_leg = 0;   // after this leg (at a corner); the leg count: not at a corner
};

class WriterErrorInjector {
 public:
  /// `profile` must outlive the injector.
  explicit WriterErrorInjector(const WriterProfile& profile) : profile_(&profile) {}

  /// The offset of the writer's copy of a character [m]: bias_offset_m in a direction drawn (one draw).
  [[nodiscard]] Vec2 draw_character_offset(std::mt19937_64& rng) const;
  /// The writer's order of a character's `stroke_count` strokes: the reference order, each stroke swapped
  /// with the next at order_error_probability (one draw at each stroke a swap could still start at).
  [[nodiscard]] std::vector<std::size_t> draw_stroke_order(std::size_t stroke_count,
                                                           std::mt19937_64& rng) const;
  /// Whether the writer means a stroke backwards, at backwards_probability (one draw).
  [[nodiscard]] bool draw_backwards(std::mt19937_64& rng) const;
  /// An attempt's errors, their probabilities and the jitter scaled by `care` in [0, 1] (a re-attempt is
  /// more careful): nine draws whatever comes of them, so that the plan does not depend on the servo rate.
  [[nodiscard]] AttemptErrors draw_attempt(double care, std::mt19937_64& rng) const;

  /// Appends to `program` a touch outside `character`'s box on the way from `from` [m]: the pen lands
  /// kStrayDistance_m outside the box side nearest `from`, slides along it and lifts. Returns the lifted
  /// pen's point [m]. `paper_z_m` is the paper's height [m].
  Vec3 add_outside_touch(std::vector<Segment>& program, const PlacedCharacter& character, const Vec3& from,
                         double paper_z_m) const;
  /// Where `errors`' hesitation goes in a stroke of `leg_count` legs (at least one).
  [[nodiscard]] static HesitationPlace place_hesitation(const AttemptErrors& errors, std::size_t leg_count);
  /// The hesitation's pause, holding still at `at` [m].
  [[nodiscard]] static Segment hesitation(const Vec3& at, const AttemptErrors& errors);
  /// The leg of `leg_count` (at least one) the pen lifts in the middle of; `leg_count` for none.
  [[nodiscard]] static std::size_t lifted_leg(const AttemptErrors& errors, std::size_t leg_count);
  /// Appends to `program` the leg `path` [m] (pen down) lifted in the middle: written up to `lift_fraction`
  /// of `proper_m` (its arc up to the seen end, past which it is follow-through), lifted, held, touched
  /// down again and written on.
  void add_lifted_leg(std::vector<Segment>& program, const std::vector<Vec3>& path, double proper_m,
                      double lift_fraction, double paper_z_m) const;

 private:
  const WriterProfile* profile_;
};

}  // namespace calligraphy::writer_detail
