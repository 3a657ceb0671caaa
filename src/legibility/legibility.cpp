#include "calligraphy/legibility/legibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>

#include "calligraphy/analysis/score.hpp"
#include "calligraphy/core/errors.hpp"
#include "core/unicode.hpp"

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
  // The final writing: pen-down runs on the paper, the ticks of attempts written again later left out.
  std::vector<std::vector<Vec2>> runs;
  bool in_run = false;
  for (const TrialSample& sample : trace) {
    const bool down =
        sample.position_m.z() - scene.layout.paper_z_m <= kPenContactThresholdM && !sample.rewritten;
    if (down && sample.position_m.allFinite()) {
      if (!in_run) runs.emplace_back();
      runs.back().push_back(sample.position_m.head<2>());
    }
    in_run = down;
  }
  // A touch that barely moves (the pen set down, lifted and set down again at a stroke's start) is no stroke:
  // the scorer's rule for a segment it ignores (ScoreOptions), so that a reader sees the strokes it scores.
  const ScoreOptions ignored;
  std::erase_if(runs, [&](const std::vector<Vec2>& run) {
    double length_m = 0.0;
    for (std::size_t i = 1; i < run.size(); ++i) length_m += (run[i] - run[i - 1]).norm();
    return run.size() < ignored.min_segment_samples || length_m < ignored.min_segment_length_m;
  });
  // Each run to the character whose box holds most of its samples (as writing_metrics assigns runs).
  std::vector<std::vector<std::vector<Vec2>>> per_character(scene.characters.size());
  for (std::vector<Vec2>& run : runs) {
    std::size_t best = 0, best_count = 0;
    for (std::size_t c = 0; c < scene.characters.size(); ++c) {
      std::size_t count = 0;
      for (const Vec2& p : run) count += scene.characters[c].bounding_box.contains(p) ? 1 : 0;
      if (count > best_count) best = c, best_count = count;
    }
    if (best_count == 0) continue;  // written off every character
    for (Vec2& p : run) p = scene.characters[best].placement.to_data(p);
    per_character[best].push_back(std::move(run));
  }
  for (std::size_t c = 0; c < scene.characters.size(); ++c) {
    std::optional<CharacterLegibility> verdict =
        character_legibility(scene.characters[c].code_point, per_character[c]);
    verdicts.push_back(verdict.value_or(CharacterLegibility{scene.characters[c].code_point, 0, ""}));
  }
  return verdicts;
}

}  // namespace calligraphy
