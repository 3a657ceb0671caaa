#pragma once
// What the trainer's window says to a learner, in the learner's terms: which device is in the hand and what
// to do with it, and one line of feedback per stroke attempt (1-based strokes, millimetres, what was off).
// Pure functions of their arguments (no window, no ImGui), so that the wording is tested on its own
// (tests/trainer/learner_text_test.cpp). docs/trainer.md, "What a learner sees", lists the lines.
#include <cstddef>
#include <optional>
#include <string>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/model/stroke_progress.hpp"

namespace calligraphy::trainer {

/// The kind of device a learner holds, as far as what they feel is concerned.
enum class LearnerDevice {
  mouse,             ///< "mouse": a pointer, no force output
  mouse_hand,        ///< "mouse-hand": the mouse moves a simulated pen that guidance pulls; nothing is felt
  haptic,            ///< a haptic device (hardware): the paper and the guidance are felt through the pen
  simulated_writer,  ///< the simulated writer writes on a simulated device: nothing to do but watch
  simulated_device,  ///< a simulated or emulated device without a hand on it (nothing is felt)
};

/// The kind of `device` (a registry name): `hardware` from the registry's listing, `simulated_writer` from
/// `--writer simulated`.
[[nodiscard]] LearnerDevice learner_device(const std::string& device, bool hardware,
                                           bool simulated_writer) noexcept;

/// The line that tells the learner what to do with the device, and what they will feel: `guidance` is the
/// trial's guidance (on a haptic device it is felt; elsewhere nothing is, and no line says "guidance on").
[[nodiscard]] std::string device_line(LearnerDevice device, bool guidance);

/// The guidance as the engineer's panel names it, true to what acts on whom: "guidance on" (felt) on a
/// haptic device only; "guidance on the simulated pen, not felt" (mouse-hand), "guidance on the simulated
/// writer's pen", "no force output: guidance not felt" (mouse, another device nothing moves); "guidance off".
[[nodiscard]] std::string guidance_words(LearnerDevice device, bool guidance);

/// "Stroke k of n" (k 1-based), or "Every stroke written" once k > n.
[[nodiscard]] std::string stroke_of(std::size_t stroke_1based, std::size_t strokes);

/// Where a point lies from a target, in millimetres and the paper's directions as the learner sees them
/// (x right, y away from the writer: "above"): "3 mm left", "2 mm left and 4 mm above", "0.5 mm right".
/// `offset_m` is the point minus the target [m]. A component less than a third of the larger one is left
/// out.
[[nodiscard]] std::string offset_words(const Vec2& offset_m);

/// How a line of feedback reads: praise, a correction, or a hint.
enum class FeedbackTone { good, fix, hint };

struct Feedback {
  std::string text;
  FeedbackTone tone = FeedbackTone::fix;
};

/// A stroke written: "Stroke 2: good, 1.2 mm off on average" when its mean deviation is at most half the
/// acceptance's limit, else "Stroke 2: written, 2.4 mm off on average; keep to the middle of the stroke".
[[nodiscard]] Feedback stroke_written(std::size_t stroke_1based, double mean_deviation_m,
                                      const StrokeAcceptance& acceptance);

/// What one refused attempt at stroke `stroke_1based` did, and what to do instead.
struct RefusedAttempt {
  std::size_t stroke_1based = 1;
  StrokeRefusal refusal = StrokeRefusal::none;
  /// The attempt's first pen-down point minus the stroke's start [m], when the attempt had points.
  std::optional<Vec2> start_offset_m;
  /// The stroke's start neighbourhood [m]: a start farther than this from the stroke's start is named.
  double start_radius_m = 0.005;
  /// wrong_order, wrong_stroke: the stroke (1-based) the attempt wrote instead, when it is known.
  std::optional<std::size_t> written_instead_1based;
};

/// "Stroke 4: too short; carry on to the end", "Stroke 3: written backwards; start at the other end",
/// "Stroke 3: started 3 mm left of the start", "That was stroke 5; stroke 4 comes first", ...
[[nodiscard]] Feedback stroke_refused(const RefusedAttempt& attempt);

/// "Here is stroke k: follow the blue path from its start" (a hint after misses).
[[nodiscard]] Feedback stroke_hint(std::size_t stroke_1based);
/// "Stroke k shown and counted as assisted".
[[nodiscard]] Feedback stroke_assisted(std::size_t stroke_1based);

}  // namespace calligraphy::trainer
