#pragma once
// The panel on the right of the trainer's window: the trial, the interaction state (SS/AS/CS/WS, paper
// Table 1), the pen, why the last attempt was refused, the per-stroke results as strokes finish, and the
// summary with the keys at the end.
#include <string>

#include "calligraphy/model/stroke_progress.hpp"
#include "trainer/layout.hpp"
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
};

/// A refusal in the learner's words: what the attempt did ("backwards") and what to do instead ("start
/// from the other end").
struct RefusalWords {
  const char* what;
  const char* advice;
};
[[nodiscard]] RefusalWords learner_words(StrokeRefusal refusal) noexcept;

void draw_panel(const WindowLayout& layout, double panel_width_px, const PanelInput& input);

}  // namespace calligraphy::trainer
