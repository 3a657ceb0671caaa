// `calligraphy bench tick [--json] [--chars CHARS] [--passes N] [--rate HZ] [--data DIR]`: the cost of one
// full servo tick over real trials (eval/tick_cost.hpp, docs/force-rendering.md).
#include <memory>
#include <string>

#include "calligraphy/core/servo_rate.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "eval/tick_cost.hpp"

namespace calligraphy::cli {
namespace {

struct TickCommand {
  bool json = false;
  std::string chars = "永我九乙心水";
  std::int64_t passes = TickCostSettings{}.passes;
  double rate_hz = TickCostSettings{}.rate_hz;
  LibraryOptions library;
};

int run_tick(const TickCommand& command) {
  TickCostSettings settings;
  settings.characters = characters_from(command.chars, "--chars");
  settings.passes = static_cast<int>(command.passes);
  settings.rate_hz = command.rate_hz;
  const CharacterSource source(command.library);
  for (const char32_t c : settings.characters) (void)source.load_named(c, "--chars");
  const TickCost cost = measure_tick_cost(library_from(command.library), settings);
  write_standard_output(command.json ? tick_cost_json(cost) : tick_cost_text(cost));
  return 0;
}

}  // namespace

void add_bench_tick_command(CLI::App& bench, Commands& commands) {
  auto command = std::make_shared<TickCommand>();
  CLI::App* app =
      commands.add(bench, "tick", "Cost of one servo tick (renderer and safety chain) over real trials",
                   [command] { return run_tick(*command); });
  add_flag(*app, "--json", command->json, "print the result as JSON");
  add_text(*app, "--chars", command->chars, "CHARS", "the characters whose trials are replayed (UTF-8)");
  add_integer(*app, "--passes", command->passes, "N", "replays of each recorded trial", 1, 1000);
  add_number(*app, "--rate", command->rate_hz, "HZ", "servo rate [Hz], in " + servo_rate_range_text(false),
             "a rate in " + servo_rate_range_text(false),
             [](double hz) { return servo_rate_allowed(hz, false); });
  add_library_options(*app, command->library, false);
}

}  // namespace calligraphy::cli
