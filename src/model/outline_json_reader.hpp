#pragma once
// Bounded reader of the `strokes` (SVG outline paths) of a hanzi-writer-data JSON document. Internal.
#include <string>
#include <string_view>
#include <vector>

namespace calligraphy::detail {

/// The outline paths, or where and why the document was refused.
struct OutlineJsonResult {
  std::vector<std::string> paths;
  bool ok = false;
  std::string where;  ///< JSON pointer (/strokes/3), "/" for the root, or "line:column L:C"
  std::string what;
};

/// Reads `strokes` with nlohmann::json's SAX parser: a non-empty array of at most kMaxCharacterStrokes
/// strings at the root; every other key is skipped; nesting deeper than kMaxJsonDepth is refused. No
/// document tree is built.
OutlineJsonResult read_outlines_json(std::string_view json);

}  // namespace calligraphy::detail
