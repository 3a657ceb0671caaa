// `calligraphy strokes [--markdown FILE] [--json]`: the table of the 39 typical strokes;
// docs/typical-strokes.md is its --markdown output.
#include <iostream>

#include "calligraphy/report/trial_report.hpp"
#include "cli/arguments.hpp"
#include "cli/commands.hpp"
#include "report/typical_strokes_report.hpp"

namespace calligraphy::cli {

int command_strokes(const Args& args) {
  const Arguments arguments(args, {"markdown"}, {"json"});
  if (!arguments.positionals().empty()) throw UsageError("strokes takes no positional arguments");
  if (const auto path = arguments.option("markdown")) write_file(*path, typical_strokes_markdown());
  if (arguments.flag("json")) {
    std::cout << typical_strokes_json().dump(2) << "\n";
  } else if (!arguments.option("markdown")) {
    std::cout << typical_strokes_text();
  }
  return 0;
}

}  // namespace calligraphy::cli
