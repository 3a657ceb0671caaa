// libFuzzer target for the character-data loader and the fitter: any byte string is either refused by
// parse_hanzi_writer_json with a DataError, or accepted within the documented bounds and then fitted
// (every median), tabulated (paper Table 3) and queried for nearest points, all without an exception.
// A crash, a sanitizer report, another exception, a timeout or an accepted value outside the bounds is
// a finding. Build (clang):
//   cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCALLIGRAPHY_BUILD_FUZZERS=ON \
//         -DCALLIGRAPHY_BUILD_TESTS=OFF -DCALLIGRAPHY_BUILD_PYTHON=OFF -DCALLIGRAPHY_BUILD_BENCH=OFF \
//         -DCALLIGRAPHY_BUILD_EXAMPLES=OFF -DCALLIGRAPHY_BUILD_TOOLS=OFF
//   cmake --build build-fuzz --target character_data_fuzzer
// Run with seeds from data/hanzi-writer-data and tests/data/hostile (a new corpus folder first):
//   build-fuzz/bin/character_data_fuzzer -dict=fuzz/character_data.dict -max_len=8192 -timeout=10 \
//         CORPUS data/hanzi-writer-data tests/data/hostile
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/fitting.hpp"
#include "calligraphy/model/nearest_point.hpp"

namespace {

using namespace calligraphy;

// A broken promise of the loader or the fitter: stop here so that libFuzzer saves the input.
void require(bool promise) {
  if (!promise) std::abort();
}

void check_accepted(const CharacterData& data) {
  require(!data.medians.empty() && data.medians.size() <= kMaxCharacterStrokes);
  std::size_t points = 0;
  for (const auto& median : data.medians) {
    require(median.size() >= 2 && median.size() <= kMaxMedianPoints);
    bool distinct = false;
    for (const Vec2& p : median) {
      require(p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxDataCoordinate);
      distinct = distinct || p != median.front();
    }
    require(distinct);
    points += median.size();
  }
  require(points <= kMaxCharacterPoints);
}

void check_fitted(const Character& character, std::size_t strokes) {
  require(character.strokes.size() == strokes);
  for (const Stroke& stroke : character.strokes) {
    require(!stroke.elements.empty());
    require(stroke.typical_id >= 1 && stroke.typical_id <= 39);
    require(stroke.attraction_factors.size() == stroke.feature_point_count());
    for (const StrokeElement& element : stroke.elements) {
      for (int i = 0; i <= element.degree; ++i)
        require(element.control[static_cast<std::size_t>(i)].allFinite());
      // The nearest point to a control point and to a point off the element: work bounded whatever the
      // element's shape (a throw here is a finding: the elements are finite and within 1e150).
      for (const Vec2& p : {element.control[1], Vec2(element.start() + Vec2(3.0, -7.0))}) {
        const NearestPoint nearest = nearest_point(element, p);
        require(std::isfinite(nearest.distance) && nearest.t >= 0.0 && nearest.t <= 1.0);
      }
    }
  }
  const CharacterTable table = character_table(character);
  require(table.typical_stroke_ids.size() == strokes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  CharacterData parsed;
  try {
    parsed = parse_hanzi_writer_json(json, U'永', "fuzz-input");
  } catch (const DataError&) {
    return 0;  // the documented outcome for bad data
  }
  check_accepted(parsed);
  const Character character = fit_character(parsed.code_point, parsed.medians, parsed.source);
  check_fitted(character, parsed.medians.size());
  return 0;
}
