#pragma once
/// \file quiz_trace.hpp
/// The quiz (analysis/quiz.hpp) over a trial's trace: the one rule by which a trace's ticks become each
/// character's pen samples, so that a saved quiz trial's record and a window judging live give the same
/// verdicts.
#include <span>
#include <vector>

#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/recorder.hpp"

namespace calligraphy {

/// The quiz events of each character of a trial's trace [`scene.characters.size()` lists]: the trace's
/// samples of each character (a tick belongs to the character whose strokes hold the active stroke; after
/// the last stroke, to the last character), as pen samples (`pen_samples`, trial/result.hpp: pen down within
/// kPenContactThresholdM of the paper), judged by `quiz_character`. The verdicts a saved quiz trial's record
/// holds; a window judging live must show the same ones.
[[nodiscard]] std::vector<std::vector<QuizEvent>> quiz_characters(const Scene& scene,
                                                                  std::span<const TrialSample> trace,
                                                                  const QuizOptions& options);

}  // namespace calligraphy
