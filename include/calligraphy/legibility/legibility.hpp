#pragma once
/// \file legibility.hpp
/// Legibility as an independent reader judges it: the written character given to an online handwriting
/// recogniser that knows nothing of this project's model, zinnia (T. Kudo, an SVM recogniser of stroke
/// features) with the Tegaki project's Simplified-Chinese model (Debian `zinnia-utils`, `libzinnia-dev`,
/// `tegaki-zinnia-simplified-chinese`). Optional: without zinnia at build time, or without its model at run
/// time, `legibility_available()` is false and every result is absent. Never on the servo path.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/core/geometry.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/recorder.hpp"

namespace calligraphy {

/// How many candidates are asked of the recogniser: top-1 and top-5 recognition are reported.
inline constexpr int kLegibilityCandidates = 5;

/// The recogniser's verdict on one written character.
struct CharacterLegibility {
  char32_t expected = 0;  ///< the character meant
  /// 1-based rank of `expected` among the recogniser's candidates, 0 when not among the first
  /// kLegibilityCandidates (or nothing was written).
  int rank = 0;
  std::string top1;  ///< the recogniser's first candidate (UTF-8), "" when nothing was written
};

/// Whether a recogniser is built in and its model could be opened (CALLIGRAPHY_ZINNIA_MODEL, else Debian's
/// /usr/share/tegaki/models/zinnia/handwriting-zh_CN.model). Any thread.
[[nodiscard]] bool legibility_available();

/// The model file in use, "" when none is available.
[[nodiscard]] std::string legibility_model_path();

/// Recognises strokes in the character's data units (hanzi-writer-data: a 1024-unit box, y up, x and y in
/// [0, 1024] and [-124, 900]), in writing order, each a polyline of at least one point. Returns nullopt
/// when no recogniser is available. Any thread (one recogniser behind a mutex). Throws InvalidArgument for
/// a point that is not finite.
[[nodiscard]] std::optional<CharacterLegibility> character_legibility(
    char32_t expected, std::span<const std::vector<Vec2>> strokes_data_units);

/// Each placed character of `scene` as the trial `trace` left it, read by the recogniser: the final writing
/// only (pen-down runs on the paper, `TrialSample::rewritten` ticks left out), each run given to the
/// character whose box holds most of its samples, in data units. One entry per character, in scene order;
/// empty when no recogniser is available.
[[nodiscard]] std::vector<CharacterLegibility> trial_legibility(const Scene& scene,
                                                                std::span<const TrialSample> trace);

}  // namespace calligraphy
