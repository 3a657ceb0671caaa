// `calligraphy strokes [--markdown FILE] [--json]`: the table of the 39 typical strokes;
// docs/typical-strokes.md is its --markdown output.
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/output.hpp"
#include "calligraphy/report/typical_strokes_report.hpp"

namespace calligraphy::cli {
namespace {

struct StrokesCommand {
  std::string markdown;
  bool json = false;
};

int run_strokes(const StrokesCommand& command) {
  require_one_standard_output({{"--json", command.json}, {"--markdown -", command.markdown == "-"}});
  FilePlan files;
  files.output("--markdown", command.markdown);
  if (!command.markdown.empty()) write_output(command.markdown, typical_strokes_markdown());
  if (command.json) {
    write_standard_output(typical_strokes_json() + "\n");
  } else if (command.markdown.empty()) {
    write_standard_output(typical_strokes_text());
  }
  return 0;
}

}  // namespace

void add_strokes_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<StrokesCommand>();
  CLI::App* app = commands.add(root, "strokes", "Print the table of the 39 typical strokes",
                               [command] { return run_strokes(*command); });
  add_output_path(*app, "--markdown", command->markdown,
                  "write the table as Markdown (docs/typical-strokes.md)", StandardOutput::allowed);
  add_flag(*app, "--json", command->json, "print the table as JSON");
}

}  // namespace calligraphy::cli
