#include "cli/writer_options.hpp"

#include <map>

#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "cli/cli_devices.hpp"

namespace calligraphy::cli {

CLI::Option* add_writer_option(CLI::App& app, std::string& target, const std::string& description,
                               const std::string& default_text, bool every_spelling) {
  // --writer's values from before it meant who writes (trial: the profile; session run: human) are
  // refused saying what to write now, so an old command line is not read as something else.
  const std::string meaning = "--writer is who writes (person or simulated); ";
  const std::map<std::string, std::string> retired{
      {"novice", meaning + "the profile is --writer-profile novice"},
      {"skilled", meaning + "the profile is --writer-profile skilled"},
      {"foreign", meaning + "the profile is --writer-profile foreign"},
      {"human", meaning + "a person writing is --writer person"},
  };
  std::vector<std::string> choices{kPersonWriter, kSimulatedWriter};
  if (every_spelling) {
    choices.clear();
    for (const std::string_view spelling : enum_spellings<TrialWriter>()) choices.emplace_back(spelling);
  }
  return add_choice(app, "--writer", target, choices, description, default_text, retired);
}

bool simulated_writer_moves(const DeviceListing& device) {
  // A simulated hand pushes a device through its hand port (the simulated device, the emulated Phantom);
  // a physical device has none, nor have the window's mouse devices, which a person moves.
  return device.capabilities.moved_by_simulated_hand;
}

TrialWriter writer_for_device(const std::string& given, const DeviceListing& device) {
  return writer_for_device(given, device.name, simulated_writer_moves(device));
}

TrialWriter writer_for_device(const std::string& given, const std::string& device_name,
                              bool moved_by_simulated_hand) {
  if (given.empty()) return moved_by_simulated_hand ? TrialWriter::simulated : TrialWriter::person;
  if (given == kSimulatedWriter && !moved_by_simulated_hand) {
    throw UsageError("--writer simulated with --device " + device_name + ": the device '" + device_name +
                     "' is moved by a person (--writer person); the simulated writer moves simulated and "
                     "emulated-phantom");
  }
  if (given == kPersonWriter && moved_by_simulated_hand) {
    throw UsageError("--writer person with --device " + device_name + ": a person cannot hold the device '" +
                     device_name +
                     "', the simulated writer moves it (--writer simulated); a person writes on a haptic "
                     "device of `calligraphy devices`, or with the mouse in `calligraphy train` (mouse, "
                     "mouse-hand)");
  }
  return given == kSimulatedWriter ? TrialWriter::simulated : TrialWriter::person;
}

}  // namespace calligraphy::cli
