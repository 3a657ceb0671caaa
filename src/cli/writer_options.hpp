#pragma once
// --writer and --writer-profile, one meaning on every command: --writer is who writes (person or
// simulated), --writer-profile is how the simulated writer writes (novice, skilled, foreign). The spellings
// the commands took before (`trial --writer novice`, `session run --writer human`) are usage errors that
// say what to write instead, so that an old command line is not read as something else.
#include <string>
#include <vector>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

/// Who writes, as --writer spells it.
inline constexpr const char* kPersonWriter = "person";
inline constexpr const char* kSimulatedWriter = "simulated";

/// --writer person|simulated into `target` (left as it is when not given: "" lets the device decide, see
/// `writer_for_device`); `default_text` is the default --help shows. `every_spelling`: every spelling of
/// TrialWriter's table, "auto" (the device's own) too, as a trial specification takes them. The values
/// --writer took before (novice, skilled, foreign, human) are usage errors saying what to write instead.
CLI::Option* add_writer_option(CLI::App& app, std::string& target, const std::string& description,
                               const std::string& default_text, bool every_spelling = false);

/// Whether the simulated writer can move `device` (it has a hand port); else a person moves it.
bool simulated_writer_moves(const DeviceListing& device);

/// Who writes on `device`: `given` ("person", "simulated", or "" for the device's own: the simulated
/// writer on a device it moves, a person on any other), never `automatic`. Throws UsageError naming
/// --writer when that writer cannot move the device.
TrialWriter writer_for_device(const std::string& given, const DeviceListing& device);
/// The same for the device called `device_name` whose kind the simulated writer moves or not
/// (`kind_moved_by_simulated_hand`): a writer it cannot have is refused also while the device cannot be used.
TrialWriter writer_for_device(const std::string& given, const std::string& device_name,
                              bool moved_by_simulated_hand);

}  // namespace calligraphy::cli
