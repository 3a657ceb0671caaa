#include "calligraphy/legibility/legibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>

#include "analysis/segmentation.hpp"
#include "calligraphy/analysis/score.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/core/unicode.hpp"

#ifdef CALLIGRAPHY_WITH_ZINNIA
#include <zinnia.h>
#endif

namespace calligraphy {
namespace {

// The recogniser's canvas: the data box, y down (zinnia reads screen coordinates). hanzi-writer-data's
// box spans y in [-124, 900] with y up, so screen y = 900 - y (its own SVG transform).
constexpr int kCanvasUnits = 1024;
constexpr double kDataTopY = 900.0;

#ifdef CALLIGRAPHY_WITH_ZINNIA
struct Recogniser {
  zinnia_recognizer_t* recogniser = nullptr;
  std::string model;
  std::mutex mutex;  // zinnia's classify is not documented as thread-safe
  ~Recogniser() {
    if (recogniser != nullptr) zinnia_recognizer_destroy(recogniser);
  }
};

std::string model_file() {
  if (const char* path = std::getenv("CALLIGRAPHY_ZINNIA_MODEL"); path != nullptr && *path != '\0')
    return path;
  return "/usr/share/tegaki/models/zinnia/handwriting-zh_CN.model";
}

// Opened once, on first use; nullptr when the model cannot be opened.
Recogniser* recogniser() {
  static std::unique_ptr<Recogniser> shared = [] {
    auto made = std::make_unique<Recogniser>();
    std::error_code error;
    const std::string file = model_file();
    if (!std::filesystem::is_regular_file(file, error)) return std::unique_ptr<Recogniser>();
    made->recogniser = zinnia_recognizer_new();
    if (made->recogniser == nullptr || zinnia_recognizer_open(made->recogniser, file.c_str()) == 0) {
      return std::unique_ptr<Recogniser>();
    }
    made->model = file;
    return made;
  }();
  return shared.get();
}
#endif

int canvas(double value) {
  return static_cast<int>(std::lround(std::clamp(value, -4.0 * kCanvasUnits, 5.0 * kCanvasUnits)));
}

}  // namespace

bool legibility_available() {
#ifdef CALLIGRAPHY_WITH_ZINNIA
  return recogniser() != nullptr;
#else
  return false;
#endif
}

std::string legibility_model_path() {
#ifdef CALLIGRAPHY_WITH_ZINNIA
  const Recogniser* shared = recogniser();
  return shared != nullptr ? shared->model : std::string();
#else
  return {};
#endif
}

std::optional<CharacterLegibility> character_legibility(
    char32_t expected, std::span<const std::vector<Vec2>> strokes_data_units) {
  for (std::size_t s = 0; s < strokes_data_units.size(); ++s) {
    for (const Vec2& point : strokes_data_units[s]) {
      if (!point.allFinite()) {
        throw InvalidArgument("character_legibility: stroke " + std::to_string(s) +
                              " has a point that is not finite");
      }
    }
  }
#ifdef CALLIGRAPHY_WITH_ZINNIA
  Recogniser* shared = recogniser();
  if (shared == nullptr) return std::nullopt;
  CharacterLegibility verdict;
  verdict.expected = expected;
  std::size_t written = 0;
  for (const std::vector<Vec2>& stroke : strokes_data_units) written += stroke.empty() ? 0 : 1;
  if (written == 0) return verdict;
  const std::string expected_text = encode_utf8(expected);
  std::lock_guard lock(shared->mutex);
  zinnia_character_t* character = zinnia_character_new();
  zinnia_character_set_width(character, kCanvasUnits);
  zinnia_character_set_height(character, kCanvasUnits);
  std::size_t id = 0;
  for (const std::vector<Vec2>& stroke : strokes_data_units) {
    if (stroke.empty()) continue;
    for (const Vec2& point : stroke)
      zinnia_character_add(character, id, canvas(point.x()), canvas(kDataTopY - point.y()));
    ++id;
  }
  zinnia_result_t* result = zinnia_recognizer_classify(shared->recogniser, character, kLegibilityCandidates);
  if (result != nullptr) {
    const std::size_t size = zinnia_result_size(result);
    for (std::size_t i = 0; i < size; ++i) {
      const char* value = zinnia_result_value(result, i);
      if (value == nullptr) continue;
      if (i == 0) verdict.top1 = value;
      if (verdict.rank == 0 && expected_text == value) verdict.rank = static_cast<int>(i) + 1;
    }
    zinnia_result_destroy(result);
  }
  zinnia_character_destroy(character);
  return verdict;
#else
  static_cast<void>(expected);
  return std::nullopt;
#endif
}

std::vector<CharacterLegibility> trial_legibility(const Scene& scene, std::span<const TrialSample> trace) {
  std::vector<CharacterLegibility> verdicts;
  if (!legibility_available() || scene.characters.empty()) return verdicts;
  // The final writing: pen-down runs on the paper without the ticks of attempts written again later (or a
  // sample that is not finite), each run given to its character as the metrics give it (writing_metrics),
  // and without the runs the scorer ignores (ScoreOptions: a touch that barely moves, the pen set down and
  // lifted at a stroke's start), so that the reader sees the strokes the scorer scores.
  std::vector<PenSample> samples = pen_samples(scene, trace);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    samples[k].pen_down = samples[k].pen_down && !trace[k].rewritten && trace[k].position_m.allFinite();
  }
  const std::vector<std::size_t> owner = trial_detail::character_of_samples(scene, samples);
  const ScoreOptions scored;
  std::vector<std::vector<std::vector<Vec2>>> per_character(scene.characters.size());
  for (const WrittenSegment& run :
       trial_detail::pen_down_segments(samples, scored.min_segment_samples, scored.min_segment_length_m)) {
    const PlacedCharacter& character = scene.characters[owner[run.begin]];
    // Ink outside every character's box is no part of a character a reader is shown.
    const auto in_box = [&](const PenSample& s) { return character.bounding_box.contains(s.position_m); };
    if (run.ignored || std::none_of(samples.begin() + static_cast<std::ptrdiff_t>(run.begin),
                                    samples.begin() + static_cast<std::ptrdiff_t>(run.end), in_box)) {
      continue;
    }
    std::vector<Vec2>& stroke = per_character[owner[run.begin]].emplace_back();
    for (std::size_t k = run.begin; k < run.end; ++k)
      stroke.push_back(character.placement.to_data(samples[k].position_m));
  }
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    std::optional<CharacterLegibility> verdict =
        character_legibility(scene.characters[c].code_point, per_character[c]);
    verdicts.push_back(verdict.value_or(CharacterLegibility{scene.characters[c].code_point, 0, ""}));
  }
  return verdicts;
}

}  // namespace calligraphy
