// `calligraphy devices`: lists every haptic device the registered backends find, with its DeviceInfo.
#include <iostream>

#include "calligraphy/devices/device_registry.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"

namespace calligraphy::cli {

int command_devices(const Args& args) {
  for (const auto& arg : args) {
    if (arg == "-h" || arg == "--help") {
      std::cout << "usage: calligraphy devices\n"
                   "Lists the haptic devices that can be opened by name, with their limits in SI units.\n";
      return 0;
    }
    throw UsageError("devices: unexpected argument '" + arg + "' (usage: calligraphy devices)");
  }
  print_device_survey(std::cout, cli_device_registry().survey());
  return 0;
}

}  // namespace calligraphy::cli
