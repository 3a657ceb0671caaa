#pragma once
// The plan of one attempt at a stroke (private to the sim module): the writer's biased copy of the stroke
// it sees, cut into legs at its corners and ending where it lifts the pen, turned into the motion program
// that takes the hand there, writes it with the attempt's errors and lifts the pen.
#include <random>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "sim/writer_error_injector.hpp"
#include "sim/writer_program.hpp"
#include "sim/writer_stroke_path.hpp"

namespace calligraphy::writer_detail {

/// What an attempt sets out to write.
struct AttemptIntent {
  const PlacedCharacter* character = nullptr;
  const PlacedStroke* stroke = nullptr;    // a stroke of `character`
  bool reversed = false;                   // written from its end
  double care = 1.0;                       // in (0, 1]: the share of the bias left on this attempt
  Vec2 character_offset_m = Vec2::Zero();  // the copy's offset of the character at full bias [m]
  AttemptErrors errors;
  Vec3 from_m = Vec3::Zero();  // where the hand is when it sets off [m]
  double paper_z_m = 0.0;      // the paper's height [m]
};

/// The stroke as the writer sees it and the program that writes it.
struct AttemptProgram {
  Polyline seen;                 // the displayed stroke in the writing direction [m]
  std::vector<Segment> program;  // from `from_m` to the pen lifted past the stroke
};

/// Plans `intent` for a writer of `profile`. Draws from `rng`, in this order, a cut for each corner of the
/// seen stroke and where the pen lifts relative to its seen end.
[[nodiscard]] AttemptProgram plan_attempt(const AttemptIntent& intent, const WriterProfile& profile,
                                          const WriterErrorInjector& injector, std::mt19937_64& rng);

}  // namespace calligraphy::writer_detail
