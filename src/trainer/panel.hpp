#pragma once
// The panel on the right of the trainer's window. The learner's view (the default): the character, stroke k
// of n, what to do with the device in use, the last line of feedback, and buttons (demonstrate, restart,
// next). The engineer's view (`train --engineer`): the trial, the interaction state (SS/AS/CS/WS, paper
// Table 1), ticks, elements, the pen and the force, why the last attempt was refused, the per-stroke
// results as strokes finish, and the summary with the keys at the end.
#include <cstddef>
#include <optional>
#include <string>

#include "calligraphy/model/stroke_progress.hpp"
#include "trainer/layout.hpp"
#include "trainer/learner_text.hpp"
#include "trainer/trial_view.hpp"

struct ImFont;

namespace calligraphy::trainer {

struct PanelInput {
  const TrialView* view = nullptr;  ///< null before the first trial
  std::string character;            ///< UTF-8
  std::string device;
  std::size_t characters = 1;       ///< in the row
  bool next_guidance = true;        ///< what G has set for the next trial
  std::string next_mode = "fixed";  ///< the next trial's guidance mode (M cycles it)
  double next_gain = 1.0;           ///< the next trial's fading gain
  bool unattended = false;
  bool quiz = false;    ///< `train --quiz`: G and M do nothing
  std::string status;   ///< a line for errors or notices
  std::string session;  ///< a study session: subject, trial i of n, phase, condition; empty otherwise
  std::string prompt;   ///< what the person is asked to do now (start, rest), shown large; may be empty
  double frame_rate_hz = 0.0;
  ImFont* large_font = nullptr;
  bool engineer = false;                              ///< the engineer's panel; else the learner's
  std::string device_line;                            ///< what to do with the device (learner_text.hpp)
  LearnerDevice device_kind = LearnerDevice::haptic;  ///< what the guidance acts on (guidance_words)
  /// A demonstration runs: the stroke being drawn (1-based) and the character's strokes.
  std::optional<std::pair<std::size_t, std::size_t>> demonstrating;
  bool practice_buttons = false;  ///< `train`: the demonstrate, restart and next buttons
  /// The character shown has its stroke outlines (a character of the bundled store has none: only its blue
  /// reference is drawn, so no stroke is yellow).
  bool outlined = true;
};

/// What a button of the panel asked for this frame.
enum class PanelAction { none, demonstrate, restart, next };

/// A refusal in the learner's words: what the attempt did ("backwards") and what to do instead ("start
/// from the other end").
struct RefusalWords {
  const char* what;
  const char* advice;
};
[[nodiscard]] RefusalWords learner_words(StrokeRefusal refusal) noexcept;

/// Draws the panel; returns the button pressed, if any.
PanelAction draw_panel(const WindowLayout& layout, double panel_width_px, const PanelInput& input);

}  // namespace calligraphy::trainer
