#pragma once
/// \file typical_strokes_report.hpp
/// The table of the 39 typical strokes (model/typical_strokes.hpp) as text, Markdown (docs/typical-strokes.md)
/// and JSON, generated from the code so that the published table cannot drift from it.
#include <string>

namespace calligraphy {

/// One line per typical stroke after a header line: ID, acronym, name, pinyin, template.
[[nodiscard]] std::string typical_strokes_text();
/// The Markdown table of docs/typical-strokes.md.
[[nodiscard]] std::string typical_strokes_markdown();
/// A JSON array (indented by 2), one object per typical stroke: id, acronym, name, pinyin, unicode ("U+31C6"
/// or null), compound, template (the pieces with their directions [deg], tolerances [deg], hook, lengths),
/// default_attraction, corner_attraction.
[[nodiscard]] std::string typical_strokes_json();

}  // namespace calligraphy
