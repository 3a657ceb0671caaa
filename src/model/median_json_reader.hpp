#pragma once
// Bounded reader of the `medians` of a hanzi-writer-data JSON document. Internal.
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::detail {

/// The medians, or where and why the document was refused.
struct MedianJsonResult {
  std::vector<std::vector<Vec2>> medians;
  bool ok = false;
  std::string where;  ///< JSON pointer (/medians/3/1/0), "/" for the root, or "line:column L:C (at ...)"
  std::string what;
};

/// Reads the medians with nlohmann::json's SAX parser (iterative: nesting costs one small frame each,
/// and the reader stops at kMaxJsonDepth), checking every bound of character_library.hpp while
/// reading, so that no document tree is built and no error text grows with the input.
MedianJsonResult read_medians_json(std::string_view json);

}  // namespace calligraphy::detail
