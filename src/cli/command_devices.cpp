// `calligraphy devices`: lists every haptic device the registered backends find, with its DeviceInfo.
#include <iostream>

#include "calligraphy/device_registry.hpp"
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
  print_device_survey(std::cout, device_registry().survey());
  return 0;
}

}  // namespace calligraphy::cli
