#pragma once
/// \file writer_log.hpp
/// What a simulated writer did, attempt by attempt: which stroke it meant to write and when, whether it
/// wrote it out of order or backwards, which errors it made and how the attempt ended. A value type for
/// tests and experiments (the scoring of the pen trace measures the same things from outside).
#include <cstddef>
#include <vector>

namespace calligraphy {

/// How an attempt at a stroke ended.
enum class AttemptEnd {
  unfinished,   ///< the trial ended during the attempt
  completed,    ///< the writer wrote its whole path and lifted the pen
  refused,      ///< the writer felt resistance and broke the attempt off (guidance refused the stroke)
  interrupted,  ///< the writer saw its stroke cleared after a lift in the middle and started it again
  /// The writer wrote its whole path at the stroke the display showed as next, lifted the pen and saw the
  /// display not take it (the stroke was refused: too short, in the wrong place, ...); it writes it again.
  not_accepted,
};

/// One attempt at one stroke.
struct WriterAttempt {
  std::size_t character = 0;     ///< character index in the scene
  std::size_t stroke = 0;        ///< stroke index within the character (the stroke the writer meant to write)
  std::size_t scene_stroke = 0;  ///< the same stroke counted over the scene
  bool reversed = false;         ///< written from its end to its start
  /// Another stroke of the character, earlier in the reference order, was not written yet (by the
  /// writer's own account) when this attempt started.
  bool out_of_order = false;
  bool follows_hint = false;     ///< the writer wrote the stroke the display hinted, after a refusal
  bool outside_touch = false;    ///< the pen touched the paper outside the character's box before it
  bool hesitation = false;       ///< the writer paused before the stroke or at a corner
  bool mid_stroke_lift = false;  ///< the pen was lifted in the middle of the stroke
  int attempt = 1;               ///< 1 for the first attempt at this stroke, 2 for the next, ...
  double start_s = 0.0;          ///< the writer set off towards the stroke [s]
  double touch_down_s = -1.0;    ///< it started writing (pen on the paper at the start) [s]; -1 never
  double end_s = -1.0;           ///< the attempt ended [s]; -1 unfinished
  AttemptEnd end = AttemptEnd::unfinished;
};

/// Every attempt in the order made, and what the writer perceived.
struct WriterLog {
  std::vector<WriterAttempt> attempts;
  std::size_t refusals = 0;      ///< attempts broken off because of resistance
  std::size_t not_accepted = 0;  ///< attempts written whole that the display did not take (seen)
  /// The writer gave up on a stroke after `max_attempts_per_stroke` attempts and moved on to the rest of
  /// its plan (docs/writer.md, "Give-up and retries").
  bool gave_up = false;
  std::size_t strokes_given_up = 0;  ///< strokes it gave up on so (each left as its last attempt left it)

  /// Attempts that were out of order / backwards / of each error kind.
  [[nodiscard]] std::size_t out_of_order_attempts() const noexcept;
  [[nodiscard]] std::size_t backwards_attempts() const noexcept;
  [[nodiscard]] std::size_t mid_stroke_lifts() const noexcept;
  [[nodiscard]] std::size_t outside_touches() const noexcept;
  [[nodiscard]] std::size_t hesitations() const noexcept;
  /// Out-of-order / backwards attempts that ended `refused`.
  [[nodiscard]] std::size_t refused_out_of_order() const noexcept;
  [[nodiscard]] std::size_t refused_backwards() const noexcept;
  /// Scene stroke indices of the `completed` attempts, in the order written.
  [[nodiscard]] std::vector<std::size_t> completed_order() const;
};

}  // namespace calligraphy
