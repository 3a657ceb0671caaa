// `calligraphy devices [--json]`: every haptic device the registered backends find, with its DeviceInfo, and
// every kind of device the commands take (the registry's backends, the emulator, the pointer devices of the
// window) with the commands that take each.
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/report/device_survey_json.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text.empty() ? "none" : text;
}

void print_device_kinds(std::ostream& out, const std::vector<DeviceKind>& kinds) {
  out << "\nKinds of device (--device NAME) and the commands that take them:\n";
  const auto padded = [](const std::string& text, std::size_t width) {
    return text + std::string(text.size() < width ? width - text.size() : 1, ' ');
  };
  out << "  " << padded("NAME", 25) << padded("WRITER", 11) << padded("COMMANDS", 28) << "WHAT\n";
  for (const DeviceKind& kind : kinds) {
    out << "  " << padded(kind.name, 25) << padded(kind.writer, 11) << padded(joined(kind.commands), 28)
        << kind.what << "\n";
  }
}

std::string survey_and_kinds_json(const DeviceSurvey& survey, const std::vector<DeviceKind>& kinds) {
  nlohmann::ordered_json document = nlohmann::ordered_json::parse(device_survey_json(survey));
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const DeviceKind& kind : kinds) {
    list.push_back({{"name", kind.name},
                    {"backend", kind.backend},
                    {"writer", kind.writer},
                    {"commands", kind.commands},
                    {"what", kind.what}});
  }
  document["kinds"] = std::move(list);
  return json_text(document, 2) + "\n";
}

}  // namespace

void add_devices_command(CLI::App& root, Commands& commands, DeviceRegistry& devices) {
  auto json = std::make_shared<bool>(false);
  CLI::App* app = commands.add(root, "devices",
                               "List the haptic devices that can be opened by name, with their limits in SI "
                               "units, and every kind of device with the commands that take it",
                               [json, &devices] {
                                 const DeviceSurvey survey = devices.survey();
                                 const std::vector<DeviceKind> kinds = device_kinds(devices);
                                 if (*json) {
                                   write_standard_output(survey_and_kinds_json(survey, kinds));
                                 } else {
                                   std::ostringstream text;
                                   print_device_survey(text, survey);
                                   print_device_kinds(text, kinds);
                                   write_standard_output(text.str());
                                 }
                                 return 0;
                               });
  add_flag(*app, "--json", *json, "print the survey and the kinds of device as JSON (SI units)");
}

}  // namespace calligraphy::cli
