// `calligraphy bench nearest [--json] [--markdown FILE] [--queries N] [--seed S]`: accuracy and speed
// of the nearest-point methods on every scenario (docs/nearest-point.md).
#include <charconv>
#include <fstream>
#include <iostream>
#include <sstream>

#include "calligraphy/errors.hpp"
#include "cli/commands.hpp"
#include "cli/nearest_point_measurement.hpp"
#include "cli/nearest_point_report.hpp"

namespace calligraphy::cli {

namespace {

constexpr const char* kUsage =
    "usage: calligraphy bench nearest [--json] [--markdown FILE] [--queries N] [--seed S]";

template <typename Integer>
Integer parse_integer(const std::string& option, const std::string& text, Integer minimum) {
  Integer value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < minimum) {
    throw UsageError(option + " expects an integer >= " + std::to_string(minimum) + ", got '" + text + "'\n" +
                     kUsage);
  }
  return value;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace

int command_bench_nearest(const Args& args) {
  bool json = false;
  std::string markdown_path;
  MeasurementSettings settings;
  std::size_t i = 0;
  if (!args.empty() && args[0] == "nearest") i = 1;  // accept the arguments with or without the sub-command
  for (; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(arg + " expects a value\n" + kUsage);
      return args[++i];
    };
    if (arg == "--json") {
      json = true;
    } else if (arg == "--markdown") {
      markdown_path = value();
    } else if (arg == "--queries") {
      settings.queries = parse_integer<int>(arg, value(), 1);
    } else if (arg == "--seed") {
      settings.seed = parse_integer<std::uint64_t>(arg, value(), 0);
    } else {
      throw UsageError("unknown argument '" + arg + "'\n" + kUsage);
    }
  }

  const std::vector<NearestPointScenario> scenarios = nearest_point_scenarios();
  const NearestPointMeasurement measurement = measure_nearest_point(scenarios, settings);
  std::string command = "calligraphy bench nearest";
  if (!markdown_path.empty()) command += " --markdown " + markdown_path;
  command += " --queries " + std::to_string(settings.queries) + " --seed " + std::to_string(settings.seed);
  const std::string section = nearest_point_markdown(measurement, scenarios, command);

  if (!markdown_path.empty()) {
    const std::string document = replace_generated_section(read_file(markdown_path), section);
    std::ofstream out(markdown_path, std::ios::binary | std::ios::trunc);
    if (!out || !(out << document) || !out.flush()) {
      throw Error("bench nearest: cannot write the Markdown file '" + markdown_path + "'");
    }
  }
  if (json) {
    std::cout << nearest_point_json(measurement);
  } else if (markdown_path.empty()) {
    std::cout << section;
  } else {
    std::cout << "wrote the table to " << markdown_path << "\n";
  }
  return 0;
}

}  // namespace calligraphy::cli
