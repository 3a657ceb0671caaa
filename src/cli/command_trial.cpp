// `calligraphy trial CHARS ...`: a whole guided writing trial at 1 kHz on the simulated device.
#include <cstdio>
#include <vector>

#include "calligraphy/character_library.hpp"
#include "calligraphy/scene.hpp"
#include "calligraphy/trial.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/trial_report.hpp"

namespace calligraphy::cli {

int command_trial(const Args& args) {
  const Arguments arguments(args, {"guidance", "writer", "seed", "data", "store", "json", "svg", "csv", "rate"}, {});
  if (arguments.positionals().size() != 1) throw UsageError("trial takes one CHARS argument, e.g. trial 永");
  const std::u32string chars = characters_from(arguments.positionals()[0]);
  const CharacterSource source(arguments);  // only these characters are read (on demand from a store)
  std::vector<Character> characters;
  for (char32_t c : chars) characters.push_back(source.load(c));
  const Scene scene = Scene::lay_out(characters);

  TrialOptions options;
  options.force.guidance = arguments.choice_or("guidance", {"on", "off"}, "on") == "on";
  const std::string writer = arguments.choice_or("writer", {"novice", "skilled"}, "novice");
  options.writer = writer == "novice" ? WriterProfile::novice() : WriterProfile::skilled();
  const double seed = arguments.number_or("seed", 0);
  if (seed < 0 || seed != static_cast<double>(static_cast<std::uint64_t>(seed))) {
    throw UsageError("--seed expects a non-negative integer");
  }
  options.seed = static_cast<std::uint64_t>(seed);
  options.rate_hz = arguments.number_or("rate", 1000.0);
  options.keep_trace = arguments.option("svg") || arguments.option("csv");

  const TrialResult result = run_simulated_trial(scene, options);
  const TrialDescription description{arguments.positionals()[0], options.force.guidance, writer, options.seed,
                                     options.rate_hz};
  print_trial_table(description, scene, result.metrics);
  if (const auto path = arguments.option("json")) write_file(*path, trial_json(description, result.metrics));
  if (const auto path = arguments.option("svg")) write_file(*path, trial_svg(scene, result));
  if (const auto path = arguments.option("csv")) write_file(*path, trial_csv(result.trace));
  return 0;
}

}  // namespace calligraphy::cli
