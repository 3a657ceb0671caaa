#pragma once
/// \file guidance_share.hpp
/// The shares h of the correction a trial's guidance took from the writer's hand, which the two-state memory
/// of a learning writer learns with (sim/writer_memory.hpp: e = (1 - x)(1 - h)): the physics of the springs
/// on the pen, mode by mode, across the stroke (shape) and along it (timing) (docs/writer.md, "Memory"). A
/// model, not a measurement of people.
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/sim/writer_memory.hpp"

namespace calligraphy {

/// The shares for a trial under `force` (its guidance, mode and the mode's parameters), a hand of stiffness
/// `hand_stiffness_n_per_m` k [N/m] > 0 and the trial's mean deviation e [m] (NaN when no stroke was
/// written). Shape, across the stroke:
///  - guidance off, or `timing` (it pulls along the stroke, correcting no shape): 0;
///  - `fixed`, `replay`: K / (K + k); `fading`: g K / (g K + k) (guidance_assistance_share);
///  - `assist_as_needed`: K / (K + k) times the share of the deviation beyond the band, max(0, 1 - b / e)
///    (the whole share when e is NaN);
///  - `error_amplification`: 1 - r with r the factor by which the field enlarges a deviation e held by the
///    hand: k / (k - g K) while the field's spring is softer than the hand and unsaturated, 1 + F_max / (k e)
///    once it saturates at F_max, the smaller of the two (1 when e is NaN), at most 1 - kMinAssistanceShare.
/// Timing, along the stroke: K / (K + k) for `timing` (its moving target) and `replay` (the teacher's point
/// at the teacher's time); 0 for the others, whose springs pull towards the nearest point of the stroke and
/// so have no component along it. The timing demonstration (AssistanceShares::timing_demonstration) is the
/// timing share of `timing` and `replay`, whose guide moves the pen in time, and 0 for the others. Throws
/// InvalidArgument for a hand stiffness that is not finite and > 0, a
/// negative deviation, or what `ForceLawParameters::validate` throws.
[[nodiscard]] AssistanceShares guidance_shares(const ForceLawParameters& force, double hand_stiffness_n_per_m,
                                               double mean_deviation_m);

}  // namespace calligraphy
