// `calligraphy score TRACE.csv --character C ...`: scores a recorded pen trace (any device, any program;
// `trial --csv` writes one) against the character laid out as `trial` places it (docs/metrics.md).
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/score_report.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/progress.hpp"

namespace calligraphy::cli {
namespace {

bool is_acceptance_field(std::string_view name) {
  for (const ParameterField<StrokeAcceptance>& entry : ParameterTable<StrokeAcceptance>::fields())
    if (entry.name == name) return true;
  return false;
}

struct ScoreCommand {
  std::string trace;
  std::string character;
  std::string units = "m";
  std::string json;
  // Only its stroke acceptance is read: set by the options `trial` has for it, so that a trial's CSV scored
  // with the trial's options credits the strokes the trial credited.
  TrialSpec spec;
  LibraryOptions library;
};

int run_score(const ScoreCommand& command) {
  const std::u32string chars = characters_from(command.character, "--character");
  check_scene_size(chars.size(), "--character");  // before any character is loaded (docs/cli.md)
  if (chars.size() != 1 && command.units == "data") {
    throw UsageError("--character: --units data takes one character (data units are one character's); got " +
                     std::to_string(chars.size()));
  }
  FilePlan files;
  files.input("TRACE", command.trace);
  add_library_inputs(files, command.library);
  files.output("--json", command.json);
  // Several characters are placed as a trial places them (Scene::lay_out), so a trial's CSV scores as
  // written.
  std::vector<Character> models;
  const CharacterSource source(command.library);
  for (const char32_t c : chars) models.push_back(source.load_named(c, "--character"));
  const Scene scene = Scene::lay_out(models);
  const PlacedCharacter& character = scene.characters.front();
  TerminalProgress progress("reading " + command.trace);  // on stderr, only when it is a terminal
  PenTraceCsvOptions options;
  options.units = command.units == "data" ? TraceUnits::data : TraceUnits::metres;
  options.progress = [&progress](std::size_t parsed, std::size_t total) { progress.update(parsed, total); };
  const std::vector<PenSample> trace = read_pen_trace_csv(command.trace, character.placement, options);
  progress.relabel("scoring " + command.trace);
  ScoreOptions score_options;
  score_options.acceptance = command.spec.acceptance;
  score_options.progress = [&progress](std::size_t matched, std::size_t total) {
    progress.update(matched, total, "segments");
  };
  const WritingMetrics metrics = writing_metrics(scene, trace, score_options);
  progress.relabel("");
  const ScoreDescription description{command.character, command.trace, command.units, trace.size()};
  if (command.json != "-") write_standard_output(score_table(description, metrics));
  if (!command.json.empty()) write_output(command.json, score_json(description, metrics));
  return 0;
}

}  // namespace

void add_score_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<ScoreCommand>();
  CLI::App* app =
      commands.add(root, "score", "Score a pen trace (CSV) against a character or a row of characters",
                   [command] { return run_score(*command); });
  add_positional(*app, "TRACE", command->trace,
                 "CSV with a header naming t [s], x, y and pen (1/0) or z [m] (or t_s, x_m, y_m, z_m as "
                 "Python's DataFrames name them); other columns are ignored, so `trial --csv` output is read "
                 "as it is",
                 "FILE");
  required(add_text(*app, "--character", command->character, "CHARS",
                    "the character(s) the trace writes, placed as a trial places them"));
  add_choice(*app, "--units", command->units, {"m", "data"},
             "units of x and y: metres on the paper as `trial` places the character, or the character's "
             "1024-unit data box (y up)");
  // Every field of the stroke acceptance, with the option, unit, range and default `trial` gives it (the
  // trial specification's schema): the miss counts, the corridor, the deviation, the shortfall and the rest.
  const TrialSpec defaults;
  for (const SchemaField& field : SchemaOf<TrialSpec>::get().fields) {
    if (is_acceptance_field(field.name)) add_schema_option(*app, field, &command->spec, &defaults);
  }
  add_output_path(*app, "--json", command->json, "write the score as JSON", StandardOutput::allowed);
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
