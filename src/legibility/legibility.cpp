#include "calligraphy/legibility/legibility.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "analysis/segmentation.hpp"
#include "calligraphy/analysis/score.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/trial/result.hpp"
#include "core/library_log.hpp"

#ifdef CALLIGRAPHY_WITH_ZINNIA
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zinnia.h>

#include <cerrno>
#include <string_view>
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
  // The model file mapped read-only: checked, then given to zinnia, which keeps pointers into it. One mapping
  // (zinnia_recognizer_open would map the file again), no copy of its 26 MB into memory of the process's own.
  void* mapped = MAP_FAILED;
  std::size_t mapped_bytes = 0;
  std::mutex mutex;  // zinnia's classify is not documented as thread-safe
  ~Recogniser() {
    if (recogniser != nullptr) zinnia_recognizer_destroy(recogniser);
    if (mapped != MAP_FAILED) ::munmap(mapped, mapped_bytes);
  }
};

// Debian's zh_CN model is 26 MB; a file far larger is not one.
constexpr std::uintmax_t kMaxModelBytes = std::uintmax_t{256} << 20;

std::string model_file() {
  if (const char* path = std::getenv("CALLIGRAPHY_ZINNIA_MODEL"); path != nullptr && *path != '\0')
    return path;
  return "/usr/share/tegaki/models/zinnia/handwriting-zh_CN.model";
}

// Why a zinnia model file cannot be used, "" when its layout is whole. zinnia trusts the file: a damaged
// count makes it allocate gigabytes (std::bad_alloc) and a damaged length read past the end. Its layout
// (zinnia 0.06, recognizer.cpp): a magic number, a version, the number of characters, then per character a
// 16-byte name, a float bias and (int index, float weight) pairs, the last of index -1. Walked here, bounded
// by the file's size, before zinnia sees it.
std::string model_damage(std::string_view bytes) {
  const auto word = [&](std::size_t at) {
    std::int32_t value = 0;
    std::memcpy(&value, bytes.data() + at, sizeof value);
    return value;
  };
  constexpr std::int32_t kMagic = 0x0f6e6fa1;
  if (bytes.size() < 12 || word(0) != kMagic) return "not a zinnia model (its magic number)";
  const std::int32_t characters = word(8);
  if (characters <= 0 || static_cast<std::size_t>(characters) > bytes.size() / 24)
    return "damaged: it declares " + std::to_string(characters) + " characters";
  std::size_t at = 12;
  for (std::int32_t c = 0; c < characters; ++c) {
    at += 16 + 4;  // name, bias
    while (true) {
      if (at + 8 > bytes.size()) return "damaged: cut in character " + std::to_string(c + 1);
      const std::int32_t index = word(at);
      at += 8;
      if (index == -1) break;
      if (index < 0) return "damaged: a feature index " + std::to_string(index);
    }
  }
  if (at != bytes.size())
    return "damaged: " + std::to_string(bytes.size() - at) + " bytes after its last character";
  return "";
}

// `file` mapped into `into` (a regular file of 1 byte to kMaxModelBytes, read-only); why not, "" when mapped.
std::string map_model(const std::string& file, Recogniser& into) {
  // O_NONBLOCK: a FIFO put in the file's place since it was found regular is refused below, never waited on.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return std::string("cannot open it: ") + std::strerror(errno);
  struct stat status {};
  std::string problem;
  if (::fstat(fd, &status) != 0) {
    problem = std::string("cannot read its size: ") + std::strerror(errno);
  } else if (!S_ISREG(status.st_mode)) {
    problem = "not a regular file";
  } else if (status.st_size == 0) {
    problem = model_damage({});  // no bytes to map: not a model, as any file without its magic number
  } else if (static_cast<std::uintmax_t>(status.st_size) > kMaxModelBytes) {
    problem = std::to_string(status.st_size) + " bytes, outside 1 to " + std::to_string(kMaxModelBytes);
  } else {
    into.mapped_bytes = static_cast<std::size_t>(status.st_size);
    into.mapped = ::mmap(nullptr, into.mapped_bytes, PROT_READ, MAP_PRIVATE, fd, 0);
    if (into.mapped == MAP_FAILED) problem = std::string("cannot map it: ") + std::strerror(errno);
  }
  ::close(fd);
  return problem;
}

// Opened once, on first use; nullptr when the model cannot be opened, said once in the library's log.
Recogniser* recogniser() {
  static std::unique_ptr<Recogniser> shared = []() -> std::unique_ptr<Recogniser> {
    const std::string file = model_file();
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error)) return nullptr;  // none installed: not a fault
    std::string problem;
    try {
      auto made = std::make_unique<Recogniser>();
      problem = map_model(file, *made);
      if (problem.empty())
        problem = model_damage(std::string_view(static_cast<const char*>(made->mapped), made->mapped_bytes));
      if (problem.empty()) {
        made->recogniser = zinnia_recognizer_new();
        if (made->recogniser != nullptr &&
            zinnia_recognizer_open_from_ptr(made->recogniser, static_cast<const char*>(made->mapped),
                                            made->mapped_bytes) != 0) {
          made->model = file;
          return made;
        }
        problem = "zinnia cannot open it";
      }
    } catch (const std::exception& e) {  // unreadable, over the bound, or zinnia's own allocation failing
      problem = e.what();
    }
    detail::library_log().warn(
        "legibility: the recogniser's model {} cannot be used ({}); trials are kept without "
        "legibility",
        file, problem);
    return nullptr;
  }();
  return shared.get();
}
#endif

int canvas(double value) {
  return static_cast<int>(std::lround(std::clamp(value, -4.0 * kCanvasUnits, 5.0 * kCanvasUnits)));
}

#ifdef CALLIGRAPHY_WITH_ZINNIA
// zinnia finds a stroke's vertices by splitting it at its farthest point, recursively, and keeps the k-th
// split in slot 2k+1 or 2k+2 of one array: a stroke that needs d nested splits (a pen shaking along a long
// path) makes it allocate 2^d slots, gigabytes past d = 27. What it is given is therefore simplified first
// (Douglas & Peucker 1973, to one canvas unit, finer than its own split threshold on normal strokes), and a
// stroke still over kMaxRecognisedPoints is thinned evenly, which bounds d, and the array, however the pen
// moved.
constexpr std::size_t kMaxRecognisedPoints = 20;

using CanvasPoint = std::array<int, 2>;

void keep_farthest(const std::vector<CanvasPoint>& points, std::size_t first, std::size_t last,
                   std::vector<bool>& kept) {
  // An explicit stack: a long stroke would otherwise recurse once per point.
  std::vector<std::pair<std::size_t, std::size_t>> spans{{first, last}};
  while (!spans.empty()) {
    const auto [a, b] = spans.back();
    spans.pop_back();
    if (b <= a + 1) continue;
    const double ax = points[a][0], ay = points[a][1], dx = points[b][0] - ax, dy = points[b][1] - ay;
    const double length = std::hypot(dx, dy);
    double farthest = 0.0;
    std::size_t at = a;
    for (std::size_t k = a + 1; k < b; ++k) {
      const double px = points[k][0] - ax, py = points[k][1] - ay;
      const double distance = length > 0.0 ? std::abs(px * dy - py * dx) / length : std::hypot(px, py);
      if (distance > farthest) farthest = distance, at = k;
    }
    if (farthest <= 1.0) continue;
    kept[at] = true;
    spans.push_back({a, at});
    spans.push_back({at, b});
  }
}

std::vector<CanvasPoint> recognisable_stroke(const std::vector<Vec2>& stroke) {
  std::vector<CanvasPoint> points;
  for (const Vec2& point : stroke) {
    const CanvasPoint p{canvas(point.x()), canvas(kDataTopY - point.y())};
    if (points.empty() || points.back() != p) points.push_back(p);
  }
  if (points.size() <= 2) return points;
  std::vector<bool> kept(points.size(), false);
  kept.front() = kept.back() = true;
  keep_farthest(points, 0, points.size() - 1, kept);
  std::vector<CanvasPoint> simplified;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (kept[k]) simplified.push_back(points[k]);
  if (simplified.size() <= kMaxRecognisedPoints) return simplified;
  std::vector<CanvasPoint> thinned;
  for (std::size_t k = 0; k < kMaxRecognisedPoints; ++k) {
    thinned.push_back(simplified[k * (simplified.size() - 1) / (kMaxRecognisedPoints - 1)]);
  }
  return thinned;
}
#endif

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
    for (const CanvasPoint& point : recognisable_stroke(stroke))
      zinnia_character_add(character, id, point[0], point[1]);
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
