// `calligraphy trial CHARS ...`: a whole guided writing trial at 1 kHz on any registered device
// (the simulated one by default), through run_trial: lock-step for devices a simulated writer
// moves, on the real-time ServoLoop otherwise or with --pacing real-time.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"

namespace calligraphy::cli {
namespace {

// The listing of `name`, or a UsageError (exit 2) naming every device that can be opened.
DeviceListing find_device(const std::string& name) {
  const DeviceSurvey survey = cli_device_registry().survey();
  const auto found = std::find_if(survey.devices.begin(), survey.devices.end(),
                                  [&](const DeviceListing& listing) { return listing.name == name; });
  if (found != survey.devices.end()) return *found;
  std::string names;
  for (const DeviceListing& listing : survey.devices) names += (names.empty() ? "" : ", ") + listing.name;
  throw UsageError("unknown device '" + name + "'; registered devices: " + (names.empty() ? "none" : names));
}

}  // namespace

int command_trial(const Args& args) {
  const Arguments arguments(args,
                            {"guidance", "writer", "seed", "data", "store", "json", "svg", "csv", "rate",
                             "device", "pacing", "realtime"},
                            {});
  if (arguments.positionals().size() != 1) throw UsageError("trial takes one CHARS argument, e.g. trial 永");
  const std::u32string chars = characters_from(arguments.positionals()[0]);
  const std::string device_name = arguments.option_or("device", "simulated");
  const DeviceListing device = find_device(device_name);
  const CharacterSource source(arguments);  // only these characters are read (on demand from a store)
  std::vector<Character> characters;
  for (char32_t c : chars) characters.push_back(source.load(c));
  const Scene scene = Scene::lay_out(characters);

  TrialOptions options;
  options.force.guidance = arguments.choice_or("guidance", {"on", "off"}, "on") == "on";
  const std::string writer = arguments.choice_or("writer", {"novice", "skilled"}, "novice");
  options.simulation.writer = writer == "novice" ? WriterProfile::novice() : WriterProfile::skilled();
  const double seed = arguments.number_or("seed", 0);
  if (seed < 0 || seed != static_cast<double>(static_cast<std::uint64_t>(seed))) {
    throw UsageError("--seed expects a non-negative integer");
  }
  options.simulation.seed = static_cast<std::uint64_t>(seed);
  options.rate_hz = arguments.number_or("rate", 1000.0);
  options.keep_trace = arguments.option("svg") || arguments.option("csv");
  const std::string pacing = arguments.choice_or("pacing", {"auto", "lock-step", "real-time"}, "auto");
  options.pacing = pacing == "lock-step"   ? TrialPacing::lock_step
                   : pacing == "real-time" ? TrialPacing::real_time
                                           : TrialPacing::automatic;
  options.loop.realtime = arguments.choice_or("realtime", {"enforce", "ignore"}, "ignore") == "enforce"
                              ? RealtimeMode::enforce
                              : RealtimeMode::ignore;

  const TrialResult result = run_trial(device_name, scene, options);
  // On hardware a person writes; the simulated writer only moves simulated and emulated devices.
  const TrialDescription description{
      arguments.positionals()[0], options.force.guidance, device.hardware ? "human" : writer,
      options.simulation.seed,    options.rate_hz,        device.name,
      device.info.model};
  print_trial_table(description, scene, result);
  // The outputs are written for an aborted trial too: they hold what was recorded before the fault.
  if (const auto path = arguments.option("json")) write_file(*path, trial_json(description, result));
  if (const auto path = arguments.option("svg")) write_file(*path, trial_svg(scene, result));
  if (const auto path = arguments.option("csv")) write_file(*path, trial_csv(result.trace));
  if (result.aborted) {
    std::fprintf(stderr, "calligraphy trial: error: the trial ended early (%s)%s%s\n", to_string(result.end),
                 result.abort_reason.empty() ? "" : ": ", result.abort_reason.c_str());
    return 1;
  }
  return 0;
}

}  // namespace calligraphy::cli
