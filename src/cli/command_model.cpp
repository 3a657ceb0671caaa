// `calligraphy model CHAR [--json] [--svg FILE]`: the character's Table-3 data (paper section 3.5) and, per
// stroke, its typical stroke, elements, feature points and attraction factors; --svg draws the model like
// the paper's Fig. 13.
#include <memory>
#include <string>

#include "calligraphy/core/unicode.hpp"
#include "calligraphy/report/model_report.hpp"
#include "calligraphy/report/model_svg.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct ModelCommand {
  std::string character;
  bool json = false;
  std::string svg;
  LibraryOptions library;
};

int run_model(const ModelCommand& command) {
  require_one_standard_output({{"--json", command.json}, {"--svg -", command.svg == "-"}});
  const std::u32string chars = characters_from(command.character, "CHAR");
  if (chars.size() != 1) {
    throw UsageError("CHAR: expects one character, got " + std::to_string(chars.size()) + ": " +
                     describe_characters(chars));
  }
  FilePlan files;
  add_library_inputs(files, command.library);
  files.output("--svg", command.svg);
  const Character character = CharacterSource(command.library).load_named(chars[0], "CHAR");
  if (!command.svg.empty()) write_output(command.svg, model_svg(character));
  if (command.json) {
    write_standard_output(model_json(character));
  } else if (command.svg != "-") {
    write_standard_output(model_text(character));
  }
  return 0;
}

}  // namespace

void add_model_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<ModelCommand>();
  CLI::App* app =
      commands.add(root, "model", "Print a character's model (paper Table 3); --svg draws it (Fig. 13)",
                   [command] { return run_model(*command); });
  add_positional(*app, "CHAR", command->character, "one character (UTF-8)");
  add_flag(*app, "--json", command->json, "print the model as JSON instead of text (data units, y up)");
  add_output_path(*app, "--svg", command->svg, "draw the model as SVG", StandardOutput::allowed);
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
