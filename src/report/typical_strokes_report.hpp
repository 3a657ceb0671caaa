#pragma once
// The table of the 39 typical strokes as text, Markdown (docs/typical-strokes.md) and JSON, generated
// from typical_strokes.hpp so that the published table cannot drift from the code.
#include <nlohmann/json.hpp>
#include <string>

namespace calligraphy::cli {

std::string typical_strokes_text();
std::string typical_strokes_markdown();
nlohmann::json typical_strokes_json();

}  // namespace calligraphy::cli
