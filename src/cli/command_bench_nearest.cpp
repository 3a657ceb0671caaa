// `calligraphy bench nearest`: accuracy and speed of the nearest-point methods on every scenario, and
// `calligraphy bench jumps`: foot-point jumps on real characters, by method (docs/nearest-point.md).
// With --markdown FILE the generated sections of that document are replaced (both, for `bench nearest`);
// the rest of the document is kept. Only a regular file is read for that; any other target (a device,
// '-') gets the generated sections alone.
#include <memory>
#include <string>

#include "calligraphy/core/atomic_file.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "eval/nearest_point_jumps.hpp"
#include "eval/nearest_point_measurement.hpp"
#include "eval/nearest_point_report.hpp"

namespace calligraphy::cli {
namespace {

std::string document_at(const std::string& path) {
  return path == "-" ? std::string() : read_file_for_update(path).value_or(std::string());
}

// Before any measurement: a document whose generated section (`marker`) has no end is refused.
void check_document(const std::string& path, const char* marker) {
  if (!path.empty()) check_generated_section(document_at(path), marker, path);
}

// The document at `path` with its generated sections replaced, or the sections alone.
std::string updated_document(const std::string& path, const std::string& section, const char* marker,
                             const std::string& jumps_section = {}) {
  std::string document = replace_generated_section(document_at(path), section, marker, path);
  if (!jumps_section.empty())
    document = replace_generated_section(document, jumps_section, kJumpsGeneratedBegin, path);
  return document;
}

// Standard output: the JSON, else the section unless it went to a document (then where it went).
void print_report(bool json, const std::string& json_text, const std::string& markdown,
                  const std::string& section) {
  if (json) {
    write_standard_output(json_text);
  } else if (markdown.empty()) {
    write_standard_output(section);
  } else if (markdown != "-") {
    write_standard_output("wrote the table to " + markdown + "\n");
  }
}

struct NearestCommand {
  bool json = false;
  std::string markdown;
  std::int64_t queries = MeasurementSettings{}.queries;
  std::uint64_t seed = MeasurementSettings{}.seed;
};

int run_nearest(const NearestCommand& command) {
  require_one_standard_output({{"--json", command.json}, {"--markdown -", command.markdown == "-"}});
  FilePlan files;  // the document is read and its generated section replaced: it is the one output
  files.output("--markdown", command.markdown);
  check_document(command.markdown, kGeneratedBegin);
  check_document(command.markdown, kJumpsGeneratedBegin);
  MeasurementSettings settings;
  settings.queries = static_cast<int>(command.queries);
  settings.seed = command.seed;
  const std::vector<NearestPointScenario> scenarios = nearest_point_scenarios();
  const NearestPointMeasurement measurement = measure_nearest_point(scenarios, settings);
  std::string invocation = "calligraphy bench nearest";
  if (!command.markdown.empty()) invocation += " --markdown " + command.markdown;
  invocation += " --queries " + std::to_string(settings.queries) + " --seed " + std::to_string(settings.seed);
  const std::string section = nearest_point_markdown(measurement, scenarios, invocation);

  if (!command.markdown.empty()) {
    // The jump measurement of `bench nearest`: seeds S, S + 1, S + 2 on every embedded character.
    JumpSettings jump_settings;
    jump_settings.seeds = {settings.seed, settings.seed + 1, settings.seed + 2};
    const JumpMeasurement jumps = measure_foot_jumps(CharacterLibrary::standard(), jump_settings);
    write_output(command.markdown, updated_document(command.markdown, section, kGeneratedBegin,
                                                    foot_jumps_markdown(jumps, invocation)));
  }
  print_report(command.json, nearest_point_json(measurement), command.markdown, section);
  return 0;
}

struct JumpsCommand {
  bool json = false;
  std::string markdown;
  std::int64_t seeds = 3;
  std::string chars;
  LibraryOptions library;
};

int run_jumps(const JumpsCommand& command) {
  require_one_standard_output({{"--json", command.json}, {"--markdown -", command.markdown == "-"}});
  FilePlan files;
  add_library_inputs(files, command.library);
  files.output("--markdown", command.markdown);
  check_document(command.markdown, kJumpsGeneratedBegin);
  JumpSettings settings;
  settings.seeds.clear();
  for (std::int64_t seed = 1; seed <= command.seeds; ++seed)
    settings.seeds.push_back(static_cast<std::uint64_t>(seed));
  if (!command.chars.empty()) settings.characters = characters_from(command.chars, "--chars");
  const CharacterSource source(command.library);
  for (const char32_t c : settings.characters) (void)source.load_named(c, "--chars");
  const JumpMeasurement measurement = measure_foot_jumps(library_from(command.library), settings);

  std::string invocation = "calligraphy bench jumps";
  if (!command.markdown.empty()) invocation += " --markdown " + command.markdown;
  invocation += " --seeds " + std::to_string(command.seeds);
  if (!command.chars.empty()) invocation += " --chars " + command.chars;
  if (!command.library.data_folder.empty()) invocation += " --data DATA";
  const std::string section = foot_jumps_markdown(measurement, invocation);
  if (!command.markdown.empty()) {
    write_output(command.markdown, updated_document(command.markdown, section, kJumpsGeneratedBegin));
  }
  print_report(command.json, foot_jumps_json(measurement), command.markdown, section);
  return 0;
}

}  // namespace

void add_bench_nearest_command(CLI::App& bench, Commands& commands) {
  auto command = std::make_shared<NearestCommand>();
  CLI::App* app = commands.add(bench, "nearest", "Accuracy and speed of the nearest-point methods",
                               [command] { return run_nearest(*command); });
  add_flag(*app, "--json", command->json, "print the rows as JSON");
  add_output_path(*app, "--markdown", command->markdown,
                  "replace the generated sections (nearest point and jumps) of this Markdown document",
                  StandardOutput::allowed);
  add_integer(*app, "--queries", command->queries, "N", "queries per scenario and degree", 1, 100000000);
  add_unsigned(*app, "--seed", command->seed, "N", "seed of the random scenarios");
}

void add_bench_jumps_command(CLI::App& bench, Commands& commands) {
  auto command = std::make_shared<JumpsCommand>();
  CLI::App* app =
      commands.add(bench, "jumps", "Foot-point jumps > 1 mm per stroke on real characters, by method",
                   [command] { return run_jumps(*command); });
  add_flag(*app, "--json", command->json, "print the rows as JSON");
  add_output_path(*app, "--markdown", command->markdown,
                  "replace the generated jumps section of this Markdown document", StandardOutput::allowed);
  add_integer(*app, "--seeds", command->seeds, "N", "trials per character, seeds 1..N", 1, 1000000);
  add_text(*app, "--chars", command->chars, "CHARS", "the characters to write (UTF-8)",
           "every embedded character");
  add_library_options(*app, command->library, false);
}

}  // namespace calligraphy::cli
