// `calligraphy score TRACE.csv --character C ...`: scores a recorded pen trace (any device, any program;
// `trial --csv` writes one) against the character laid out as `trial` places it (docs/metrics.md).
#include <cstddef>
#include <memory>
#include <string>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/score_report.hpp"
#include "calligraphy/trial/score.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/progress.hpp"

namespace calligraphy::cli {
namespace {

struct ScoreCommand {
  std::string trace;
  std::string character;
  std::string units = "m";
  std::string json;
  LibraryOptions library;
};

int run_score(const ScoreCommand& command) {
  const std::u32string chars = characters_from(command.character, "--character");
  if (chars.size() != 1) {
    throw UsageError("--character: expects one character, got " + std::to_string(chars.size()));
  }
  FilePlan files;
  files.input("TRACE", command.trace);
  add_library_inputs(files, command.library);
  files.output("--json", command.json);
  const Scene scene = Scene::lay_out({CharacterSource(command.library).load(chars[0])});
  const PlacedCharacter& character = scene.characters.front();
  TerminalProgress progress("reading " + command.trace);  // on stderr, only when it is a terminal
  PenTraceCsvOptions options;
  options.units = command.units == "data" ? TraceUnits::data : TraceUnits::metres;
  options.progress = [&progress](std::size_t parsed, std::size_t total) { progress.update(parsed, total); };
  const std::vector<PenSample> trace = read_pen_trace_csv(command.trace, character.placement, options);
  progress.relabel("scoring " + command.trace);
  ScoreOptions score_options;
  score_options.progress = [&progress](std::size_t matched, std::size_t total) {
    progress.update(matched, total, "segments");
  };
  const CharacterScore score = score_trace(character, trace, score_options);
  progress.relabel("");
  const ScoreDescription description{command.character, command.trace, command.units, trace.size()};
  if (command.json != "-") write_standard_output(score_table(description, score));
  if (!command.json.empty()) write_output(command.json, score_json(description, score));
  return 0;
}

}  // namespace

void add_score_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<ScoreCommand>();
  CLI::App* app = commands.add(root, "score", "Score a pen trace (CSV) against a character",
                               [command] { return run_score(*command); });
  add_positional(*app, "TRACE", command->trace,
                 "CSV with a header naming t [s], x, y and pen (1/0) or z [m]; other columns are ignored, "
                 "so `trial --csv` output is read as it is",
                 "FILE");
  required(add_text(*app, "--character", command->character, "C", "the character the trace writes"));
  add_choice(*app, "--units", command->units, {"m", "data"},
             "units of x and y: metres on the paper as `trial` places the character, or the character's "
             "1024-unit data box (y up)");
  add_output_path(*app, "--json", command->json, "write the score as JSON", StandardOutput::allowed);
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
