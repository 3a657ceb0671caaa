#include "cli/app.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <memory>
#include <system_error>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy::cli {
namespace {

#ifndef CALLIGRAPHY_VERSION
#error "CALLIGRAPHY_VERSION must be defined (from PROJECT_VERSION)"
#endif
constexpr const char* kVersion = "calligraphy " CALLIGRAPHY_VERSION;

[[noreturn]] void invalid(const std::string& name, const std::string& expectation, const std::string& value) {
  std::string message = "expects " + expectation + ", got '" + value + "'";
  if (value.rfind("-", 0) == 0 && value.size() > 1 && !std::isdigit(static_cast<unsigned char>(value[1]))) {
    message += " (an option where a value belongs?)";
  }
  throw CLI::ValidationError(name, message);
}

template <typename Integer>
bool parse_integer(const std::string& text, Integer& value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value, 10);
  return error == std::errc() && stop == end && !text.empty();
}

bool parse_number(const std::string& text, double& value) {
  const std::optional<double> parsed = parse_finite_double(text);
  if (parsed) value = *parsed;
  return parsed.has_value();
}

// An option taking exactly one value, handed to `parse` (which stores it or throws ValidationError).
CLI::Option* add_single(CLI::App& app, const std::string& name, const std::string& value_name,
                        const std::string& description, const std::string& default_text,
                        std::function<void(const std::string&)> parse) {
  CLI::Option* option = app.add_option(
      name,
      [parse, name](const CLI::results_t& results) {
        if (results.size() > 1) {
          throw CLI::ValidationError(name,
                                     "given " + std::to_string(results.size()) + " times; give it once");
        }
        parse(results.front());
        return true;
      },
      description + (default_text.empty() ? "" : " (default: " + default_text + ")"));
  option->type_size(1);
  option->expected(1);
  option->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);  // so that a repeat is seen, and refused
  option->option_text(value_name);
  return option;
}

// Text that starts with '-' is an option that took the place of a value (CLI11 hands it over).
void require_not_option_like(const std::string& name, const std::string& value, const std::string& what) {
  if (value.empty()) throw CLI::ValidationError(name, "expects " + what + ", got an empty value");
  if (value.front() == '-') invalid(name, what, value);
}

}  // namespace

CLI::App* Commands::add(CLI::App& parent, const std::string& name, const std::string& description,
                        std::function<int()> run) {
  CLI::App* app = parent.add_subcommand(name, description);
  app->set_version_flag("--version", kVersion, "Print the program's version and exit");
  app->add_flag(
      "--verbose", verbose_,
      "Also show the library's info lines (device start-up, the servo loop's statistics) on standard "
      "error; without it only its warnings");
  commands_.emplace_back(app, std::move(run));
  return app;
}

CLI::App* Commands::add_group(CLI::App& parent, const std::string& name, const std::string& description) {
  CLI::App* app = parent.add_subcommand(name, description);
  app->set_version_flag("--version", kVersion, "Print the program's version and exit");
  app->require_subcommand(1);
  return app;
}

int Commands::run_selected() const {
  for (const auto& [app, run] : commands_) {
    if (app->parsed()) return run();
  }
  throw UsageError("no command given");
}

void configure_root(CLI::App& root) {
  // A flag takes no value: `--json=yes` or `--verbose=0` is a usage error, not a value CLI11 reads as true
  // or false. Every command's options inherit this default (the commands are added after it).
  root.option_defaults()->disable_flag_override();
  root.set_version_flag("--version", kVersion, "Print the program's version and exit");
  root.require_subcommand(1);
  auto formatter = std::make_shared<CLI::Formatter>();
  formatter->column_width(40);
  root.formatter(formatter);
  root.footer(
      "Exit status: 0 success; 1 a library or I/O error, an aborted trial, or a failed check; 2 wrong usage; "
      "3 an internal error; 4 the trainer window lost its display (the running trial kept); 128 + N stopped "
      "by signal N (130 SIGINT, 143 SIGTERM, 129 SIGHUP, 138 SIGUSR1, 140 SIGUSR2, 152 SIGXCPU). Every "
      "output file is written whole or not at all; '-' as an output file means standard output. docs/cli.md "
      "describes every command.");
}

void parse_command_line(CLI::App& root, int argc, char** argv) {
  // The words before `--`: after it every word is an argument, `--help` a file of that name.
  std::vector<std::string_view> options;
  for (int i = 1; i < argc && std::string_view(argv[i]) != "--"; ++i) options.emplace_back(argv[i]);
  const auto given = [&options](std::string_view word) {
    return std::find(options.begin(), options.end(), word) != options.end();
  };
  try {
    root.parse(argc, argv);
  } catch (const CLI::Success&) {
    throw;
  } catch (const CLI::ParseError&) {
    // CLI11 checks the values (`--seed 2x`, an option given twice) before it looks for --help, and stops at
    // the first wrong word: what was asked for is answered all the same, the version first as when nothing
    // is wrong. The commands given so far are parsed, so the help is the deepest one's.
    if (given("--version")) throw CLI::CallForVersion(kVersion, 0);
    if (given("--help") || given("-h")) throw CLI::CallForHelp();
    throw;
  }
  // CLI11 reads `--json=` as `--json`: a flag given an empty value is refused as one given any other. The
  // option a word names is the deepest command's, else that of a group given before it.
  const CLI::App* command = &root;
  while (!command->get_subcommands().empty()) command = command->get_subcommands().front();
  for (const std::string_view word : options) {
    if (!word.starts_with("--") || !word.ends_with('=') || word.find('=') != word.size() - 1) continue;
    const std::string name(word.substr(0, word.size() - 1));
    for (const CLI::App* app = command; app != nullptr; app = app->get_parent()) {
      const CLI::Option* option = app->get_option_no_throw(name);
      if (option == nullptr) continue;
      if (option->get_items_expected_max() == 0) throw CLI::ArgumentMismatch::FlagOverride(name.substr(2));
      break;
    }
  }
}

CLI::Option* add_flag(CLI::App& app, const std::string& name, bool& target, const std::string& description) {
  CLI::Option* option = app.add_flag(name, target, description);
  return option;
}

CLI::Option* add_integer(CLI::App& app, const std::string& name, std::int64_t& target,
                         const std::string& value_name, const std::string& description, std::int64_t minimum,
                         std::int64_t maximum, const std::string& default_text) {
  const std::string expectation = "an integer in " + std::to_string(minimum) + ".." + std::to_string(maximum);
  const std::string shown = default_text.empty() ? std::to_string(target) : default_text;
  // The range in the help as the schema's integer options write it ("0..1000"), so that no option's
  // bounds are found only by trying them.
  const std::string ranged = description + ", " + std::to_string(minimum) + ".." + std::to_string(maximum);
  return add_single(app, name, value_name, ranged, shown, [=, &target](const std::string& text) {
    std::int64_t value = 0;
    // Decimal digits only (docs/cli.md, "Numbers"): a sign only where a negative number is allowed, so a
    // count that starts at 0 refuses '-0' as it refuses '-1'.
    const bool sign_allowed = minimum < 0 || !text.starts_with('-');
    if (!sign_allowed || !parse_integer(text, value) || value < minimum || value > maximum)
      invalid(name, expectation, text);
    target = value;
  });
}

CLI::Option* add_unsigned(CLI::App& app, const std::string& name, std::uint64_t& target,
                          const std::string& value_name, const std::string& description) {
  return add_single(app, name, value_name, description + ", 0..18446744073709551615", std::to_string(target),
                    [=, &target](const std::string& text) {
                      std::uint64_t value = 0;
                      if (!parse_integer(text, value))
                        invalid(name, "an integer in 0..18446744073709551615", text);
                      target = value;
                    });
}

CLI::Option* add_number(CLI::App& app, const std::string& name, double& target, const std::string& value_name,
                        const std::string& description, const std::string& expectation,
                        std::function<bool(double)> valid, const std::string& default_text) {
  return add_single(app, name, value_name, description,
                    default_text.empty() ? shortest_decimal(target) : default_text,
                    [=, &target](const std::string& text) {
                      double value = 0.0;
                      if (!parse_number(text, value) || !valid(value)) invalid(name, expectation, text);
                      target = value;
                    });
}

CLI::Option* add_number_list(CLI::App& app, const std::string& name, std::vector<double>& target,
                             const std::string& value_name, const std::string& description,
                             const std::string& expectation, std::function<bool(double)> valid) {
  std::string default_text;
  for (double value : target) default_text += (default_text.empty() ? "" : ",") + shortest_decimal(value);
  return add_single(app, name, value_name, description, default_text, [=, &target](const std::string& text) {
    std::vector<double> values;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = text.find(',', start);
      const std::string item =
          text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      double value = 0.0;
      if (!parse_number(item, value) || !valid(value)) {
        invalid(name, "a comma-separated list of " + expectation, text);
      }
      values.push_back(value);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    target = values;
  });
}

std::vector<std::string> name_choices(std::span<const std::string_view> names) {
  return {names.begin(), names.end()};
}

CLI::Option* add_choice(CLI::App& app, const std::string& name, std::string& target,
                        const std::vector<std::string>& choices, const std::string& description,
                        const std::string& default_text, const std::map<std::string, std::string>& retired) {
  std::string list;
  for (const auto& choice : choices) list += (list.empty() ? "" : "|") + choice;
  const std::string shown = default_text.empty() ? target : default_text;
  return add_single(app, name, list, description, shown, [=, &target](const std::string& text) {
    for (const auto& choice : choices) {
      if (choice == text) {
        target = text;
        return;
      }
    }
    if (const auto hint = retired.find(text); hint != retired.end()) {
      throw CLI::ValidationError(name + " " + text + ": " + hint->second);
    }
    invalid(name, list, text);
  });
}

CLI::Option* add_schema_option(CLI::App& app, const SchemaField& field, void* object, const void* defaults) {
  const std::string name(field.option);
  std::string description(field.doc);
  const std::string_view unit = field.option_unit.empty() ? field.unit : field.option_unit;
  if (!unit.empty()) description += " [" + std::string(unit) + "]";
  ParameterRange range = field.range;  // in the option's unit
  range.low *= field.option_factor;
  range.high *= field.option_factor;
  if (field.kind == FieldKind::number && field.option_whole) {
    description += ", " + whole_option_range_text(field);  // as the integer options write theirs
  } else if (field.kind == FieldKind::number) {
    description += ", " + range.text(unit);
  } else if (field.kind == FieldKind::integer) {
    description += ", " + field.range_text();
  }
  const std::string value_name =
      field.option_value_name.empty() ? field.range_text() : std::string(field.option_value_name);
  return add_single(app, name, value_name, description, field_text(field, defaults),
                    [name, value_name, unit, range, &field, object](const std::string& text) {
                      // A number may be negative; other values that start with '-' are an option in their
                      // place.
                      if (field.kind != FieldKind::number && field.kind != FieldKind::integer)
                        require_not_option_like(name, text, value_name);
                      try {
                        set_field_from_text(field, object, text);
                        if (field.kind == FieldKind::number)  // its range, in the option's unit
                          check_parameter(field.name,
                                          field.get_number(field, object, 0) * field.option_factor, unit,
                                          range);
                      } catch (const InvalidArgument& e) {
                        throw CLI::ValidationError(name, e.what());
                      }
                    });
}

CLI::Option* add_text(CLI::App& app, const std::string& name, std::string& target,
                      const std::string& value_name, const std::string& description,
                      const std::string& default_text) {
  const std::string shown = target.empty() ? default_text : target;
  return add_single(app, name, value_name, description, shown, [=, &target](const std::string& text) {
    require_not_option_like(name, text, value_name);
    target = text;
  });
}

CLI::Option* add_repeated_text(CLI::App& app, const std::string& name, std::vector<std::string>& target,
                               const std::string& value_name, const std::string& description) {
  CLI::Option* option = app.add_option(
      name,
      [name, value_name, &target](const CLI::results_t& results) {
        for (const std::string& text : results) {
          require_not_option_like(name, text, value_name);
          target.push_back(text);
        }
        return true;
      },
      description + " (default: none)");
  option->type_size(1);
  option->expected(1);
  option->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);  // every repeat is kept
  option->option_text(value_name);
  return option;
}

CLI::Option* add_input_path(CLI::App& app, const std::string& name, std::string& target,
                            const std::string& value_name, const std::string& description,
                            const std::string& default_text) {
  return add_single(app, name, value_name, description, default_text, [=, &target](const std::string& text) {
    // `-` is standard output for an output; for an input it is refused here, saying so, as the readers say
    // it of a `-` given as an argument.
    if (text == "-") {
      throw CLI::ValidationError(name,
                                 "expects a " + value_name + " name, got '-' (standard input is not read)");
    }
    require_not_option_like(name, text, "a " + value_name + " name");
    target = text;
  });
}

CLI::Option* add_output_path(CLI::App& app, const std::string& name, std::string& target,
                             const std::string& description, StandardOutput standard_output) {
  const bool allowed = standard_output == StandardOutput::allowed;
  const std::string full = description + (allowed ? "; '-' writes it to standard output" : "");
  return add_single(
      app, name, allowed ? "FILE|-" : "FILE", full, "not written", [=, &target](const std::string& text) {
        if (text == "-" && !allowed) {
          throw CLI::ValidationError(name, "cannot write to standard output ('-'): give a file name");
        }
        if (text != "-") require_not_option_like(name, text, "a file name");
        target = text;
      });
}

CLI::Option* add_output_folder(CLI::App& app, const std::string& name, std::string& target,
                               const std::string& description, const std::string& default_text) {
  return add_single(app, name, "DIR", description, default_text, [=, &target](const std::string& text) {
    if (text == "-") throw CLI::ValidationError(name, "expects a folder, got '-' (standard output)");
    require_not_option_like(name, text, "a folder name");
    target = text;
  });
}

CLI::Option* required(CLI::Option* option) {
  option->required();
  std::string description = option->get_description();
  const auto default_start = description.rfind(" (default: ");
  if (default_start != std::string::npos) description.erase(default_start);  // a required option has none
  option->description(description + " (required)");
  return option;
}

CLI::Option* with_default(CLI::Option* option, const std::string& default_text) {
  std::string description = option->get_description();
  const auto default_start = description.rfind(" (default: ");
  if (default_start != std::string::npos) description.erase(default_start);
  option->description(description + " (default: " + default_text + ")");
  return option;
}

namespace {

// The check of a positional argument: an empty file or folder name is wrong usage naming the argument, not
// a missing file called "" (whose error would name nothing).
CLI::Option* positional_checked(CLI::Option* option, const std::string& value_name) {
  option->required();
  option->type_name(value_name);
  if (value_name == "FILE" || value_name == "DIR") {
    const std::string expectation = "expects a " + value_name + " name, got an empty value";
    option->check(CLI::Validator(
        [expectation](const std::string& text) { return text.empty() ? expectation : std::string(); }, ""));
  }
  return option;
}

}  // namespace

CLI::Option* add_positional(CLI::App& app, const std::string& name, std::string& target,
                            const std::string& description, const std::string& value_name) {
  return positional_checked(app.add_option(name, target, description), value_name);
}

CLI::Option* add_positional_list(CLI::App& app, const std::string& name, std::vector<std::string>& target,
                                 const std::string& description, const std::string& value_name) {
  return positional_checked(app.add_option(name, target, description), value_name);
}

void require_one_standard_output(const std::vector<std::pair<std::string, bool>>& uses) {
  std::string names;
  int count = 0;
  for (const auto& [name, writes] : uses) {
    if (!writes) continue;
    names += (names.empty() ? "" : " and ") + name;
    ++count;
  }
  if (count > 1) {
    throw UsageError(names + " would all write standard output; give all but one of them a file name");
  }
}

}  // namespace calligraphy::cli
