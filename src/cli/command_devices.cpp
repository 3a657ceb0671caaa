// `calligraphy devices [--json]`: every haptic device the registered backends find, with its DeviceInfo.
#include <memory>
#include <sstream>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/report/device_survey_json.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {

void add_devices_command(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  auto json = std::make_shared<bool>(false);
  CLI::App* app = commands.add(root, "devices",
                               "List the haptic devices that can be opened by name, with their "
                               "limits in SI units",
                               [json, &devices] {
                                 const DeviceSurvey survey = devices.survey();
                                 if (*json) {
                                   write_standard_output(device_survey_json(survey));
                                 } else {
                                   std::ostringstream text;
                                   print_device_survey(text, survey);
                                   write_standard_output(text.str());
                                 }
                                 return 0;
                               });
  add_flag(*app, "--json", *json, "print the survey as JSON (SI units)");
}

}  // namespace calligraphy::cli
