// `calligraphy bench nearest [--json] [--markdown FILE] [--queries N] [--seed S]`: accuracy and speed
// of the nearest-point methods on every scenario, and `calligraphy bench jumps [--json] [--markdown FILE]
// [--seeds N] [--chars CHARS]`: foot-point jumps on real characters, by method (docs/nearest-point.md).
// `bench nearest --markdown` regenerates both sections of the document.
#include <charconv>
#include <fstream>
#include <iostream>
#include <sstream>

#include "calligraphy/core/errors.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "eval/generated_document.hpp"
#include "eval/nearest_point_jumps.hpp"
#include "eval/nearest_point_measurement.hpp"
#include "eval/nearest_point_report.hpp"

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

void write_document(const std::string& path, const std::string& document) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out || !(out << document) || !out.flush()) {
    throw Error("bench: cannot write the Markdown file '" + path + "'");
  }
}

// The jump measurement of `bench nearest`: seeds S, S + 1, S + 2 on every embedded character.
JumpSettings jump_settings_for_seed(std::uint64_t seed) {
  JumpSettings settings;
  settings.seeds = {seed, seed + 1, seed + 2};
  return settings;
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

  // Checked before the minutes of measuring.
  const std::string document = markdown_path.empty() ? std::string() : read_generated_document(markdown_path);
  const std::vector<NearestPointScenario> scenarios = nearest_point_scenarios();
  const NearestPointMeasurement measurement = measure_nearest_point(scenarios, settings);
  std::string command = "calligraphy bench nearest";
  if (!markdown_path.empty()) command += " --markdown " + markdown_path;
  command += " --queries " + std::to_string(settings.queries) + " --seed " + std::to_string(settings.seed);
  const std::string section = nearest_point_markdown(measurement, scenarios, command);

  if (!markdown_path.empty()) {
    const JumpMeasurement jumps = measure_foot_jumps(jump_settings_for_seed(settings.seed));
    std::string updated = replace_generated_section(document, section);
    updated = replace_generated_section(updated, foot_jumps_markdown(jumps, command), kJumpsGeneratedBegin);
    write_document(markdown_path, updated);
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

int command_bench_jumps(const Args& args) {
  constexpr const char* kJumpsUsage =
      "usage: calligraphy bench jumps [--json] [--markdown FILE] [--seeds N] [--chars CHARS]";
  bool json = false;
  std::string markdown_path;
  std::string chars;
  int seed_count = 3;
  std::size_t i = 0;
  if (!args.empty() && args[0] == "jumps") i = 1;
  for (; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(arg + " expects a value\n" + kJumpsUsage);
      return args[++i];
    };
    if (arg == "--json") {
      json = true;
    } else if (arg == "--markdown") {
      markdown_path = value();
    } else if (arg == "--seeds") {
      seed_count = parse_integer<int>(arg, value(), 1);
    } else if (arg == "--chars") {
      chars = value();
    } else {
      throw UsageError("unknown argument '" + arg + "'\n" + kJumpsUsage);
    }
  }
  const std::string document = markdown_path.empty() ? std::string() : read_generated_document(markdown_path);
  JumpSettings settings;
  settings.seeds.clear();
  for (int seed = 1; seed <= seed_count; ++seed) settings.seeds.push_back(static_cast<std::uint64_t>(seed));
  if (!chars.empty()) settings.characters = characters_from(chars);
  const JumpMeasurement measurement = measure_foot_jumps(settings);

  std::string command = "calligraphy bench jumps";
  if (!markdown_path.empty()) command += " --markdown " + markdown_path;
  command += " --seeds " + std::to_string(seed_count);
  if (!chars.empty()) command += " --chars " + chars;
  const std::string section = foot_jumps_markdown(measurement, command);
  if (!markdown_path.empty()) {
    write_document(markdown_path, replace_generated_section(document, section, kJumpsGeneratedBegin));
  }
  if (json) {
    std::cout << foot_jumps_json(measurement);
  } else if (markdown_path.empty()) {
    std::cout << section;
  } else {
    std::cout << "wrote the table to " << markdown_path << "\n";
  }
  return 0;
}

}  // namespace calligraphy::cli
