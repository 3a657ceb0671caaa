#include "calligraphy/trial/quiz_trace.hpp"

#include <cstddef>

#include "calligraphy/trial/result.hpp"

namespace calligraphy {

std::vector<std::vector<QuizEvent>> quiz_characters(const Scene& scene, std::span<const TrialSample> trace,
                                                    const QuizOptions& options) {
  const std::vector<PenSample> pen = pen_samples(scene, trace);
  std::vector<std::vector<QuizEvent>> events;
  events.reserve(scene.characters.size());
  std::size_t first = 0;  // the character's first stroke, over the whole scene
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    const std::size_t last = first + scene.characters[c].strokes.size();  // one past
    const bool final_character = c + 1 == scene.characters.size();
    std::vector<PenSample> samples;
    for (std::size_t i = 0; i < trace.size(); ++i) {
      const std::size_t stroke = trace[i].stroke;
      if (stroke >= first && (stroke < last || final_character)) samples.push_back(pen[i]);
    }
    events.push_back(quiz_character(scene.characters[c], samples, options));
    first = last;
  }
  return events;
}

}  // namespace calligraphy
