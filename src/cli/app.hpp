#pragma once
// The command-line framework of `calligraphy`, on CLI11: commands register a subcommand and the function
// that runs it; options are parsed strictly (the whole value, integers exactly, within a range), reject
// values that look like options, and show their unit and default in --help. A parse error is a
// CLI::ParseError naming the option; main() prints it on one line and exits with status 2.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calligraphy/core/schema.hpp"

namespace calligraphy::cli {

/// Wrong usage found after parsing (a device no backend knows, options that cannot go together):
/// main() prints the message and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The subcommands and what runs each. The function returns the process exit status.
class Commands {
 public:
  /// A subcommand of `parent` with -h/--help and --version, run by `run` when it is the one given.
  CLI::App* add(CLI::App& parent, const std::string& name, const std::string& description,
                std::function<int()> run);
  /// A subcommand that only groups others (corpus, bench): one of them is required.
  CLI::App* add_group(CLI::App& parent, const std::string& name, const std::string& description);
  /// Runs the subcommand given on the command line; throws UsageError when there is none.
  [[nodiscard]] int run_selected() const;
  /// Whether `--verbose` was given: the library's info lines (device start-up, the servo loop's statistics)
  /// are shown too, not only its warnings. Every command takes it.
  [[nodiscard]] bool verbose() const noexcept { return verbose_; }

 private:
  std::vector<std::pair<CLI::App*, std::function<int()>>> commands_;
  bool verbose_ = false;
};

/// Sets up the program's root: version flag, help layout, one subcommand required.
void configure_root(CLI::App& root);

/// Parses the command line (`argc`, `argv` as main() has them) into `root`'s commands. `--version` and
/// `-h`/`--help` are answered (CLI::CallForVersion, CLI::CallForHelp) whatever is wrong beside them, and a
/// flag given an empty value (`--json=`) is refused as `--json=yes` is (CLI::ArgumentMismatch). Other
/// errors are the CLI::ParseError CLI11 throws.
void parse_command_line(CLI::App& root, int argc, char** argv);

// ---- Options -----------------------------------------------------------------------------------
// `value_name` is what --help shows after the option (e.g. "HZ", "FILE"); `description` should give the
// unit in brackets; the default is appended as "(default: ...)".

/// A flag (no value).
CLI::Option* add_flag(CLI::App& app, const std::string& name, bool& target, const std::string& description);

/// An integer in minimum..maximum, decimal digits only (a leading '-' for a negative one). The default
/// shown is `target`, or `default_text` when given.
CLI::Option* add_integer(CLI::App& app, const std::string& name, std::int64_t& target,
                         const std::string& value_name, const std::string& description, std::int64_t minimum,
                         std::int64_t maximum, const std::string& default_text = "");
/// An unsigned 64-bit integer, parsed exactly (e.g. a seed up to 18446744073709551615).
CLI::Option* add_unsigned(CLI::App& app, const std::string& name, std::uint64_t& target,
                          const std::string& value_name, const std::string& description);
/// A finite decimal number for which `valid` holds; `expectation` says what is valid ("a number > 0"). The
/// default shown is `target`, or `default_text` when given ("none" for an option without a default).
CLI::Option* add_number(CLI::App& app, const std::string& name, double& target, const std::string& value_name,
                        const std::string& description, const std::string& expectation,
                        std::function<bool(double)> valid, const std::string& default_text = "");
/// A comma-separated list of finite numbers for which `valid` holds.
CLI::Option* add_number_list(CLI::App& app, const std::string& name, std::vector<double>& target,
                             const std::string& value_name, const std::string& description,
                             const std::string& expectation, std::function<bool(double)> valid);
/// One of `choices`. The default shown is `target`, or `default_text` when given. A value of `retired`
/// (one the option took before it changed meaning) is refused with its message, which says what to write
/// instead.
CLI::Option* add_choice(CLI::App& app, const std::string& name, std::string& target,
                        const std::vector<std::string>& choices, const std::string& description,
                        const std::string& default_text = "",
                        const std::map<std::string, std::string>& retired = {});
/// A list of names (`writer_profile_names()`) as `add_choice` takes them.
std::vector<std::string> name_choices(std::span<const std::string_view> names);
/// Every spelling of enumeration `E` (its EnumTable, core/schema.hpp), as `add_choice` takes them.
template <typename E>
std::vector<std::string> enum_choices() {
  return name_choices(enum_spellings<E>());
}
/// Free text (characters, a device name). `default_text` describes the default when `target` is empty.
CLI::Option* add_text(CLI::App& app, const std::string& name, std::string& target,
                      const std::string& value_name, const std::string& description,
                      const std::string& default_text = "");
/// Free text that may be given many times (`--writer-param a=1 --writer-param b=2`), each value in turn
/// appended to `target`; "(default: none)" in --help.
CLI::Option* add_repeated_text(CLI::App& app, const std::string& name, std::vector<std::string>& target,
                               const std::string& value_name, const std::string& description);
/// A file or folder that is read.
CLI::Option* add_input_path(CLI::App& app, const std::string& name, std::string& target,
                            const std::string& value_name, const std::string& description,
                            const std::string& default_text);

/// Whether an output may be standard output.
enum class StandardOutput { allowed, refused };
/// A file that is written (`write_output`); "-" means standard output when allowed.
CLI::Option* add_output_path(CLI::App& app, const std::string& name, std::string& target,
                             const std::string& description, StandardOutput standard_output);

/// A folder that is written in (DIR in --help; "-" refused).
CLI::Option* add_output_folder(CLI::App& app, const std::string& name, std::string& target,
                               const std::string& description, const std::string& default_text);

/// The option of schema field `field` (calligraphy/core/schema.hpp) of the struct at `object`, which must
/// outlive the parse: its name, value name, help (doc, unit, range) and default (from `defaults`, the
/// struct's default instance) from the schema; its text set once by the schema's parser
/// (`set_field_from_text`), an error naming the option. The range is the struct's check to apply
/// (`check_schema`, `validate`).
CLI::Option* add_schema_option(CLI::App& app, const SchemaField& field, void* object, const void* defaults);

/// Makes an option required and says so in --help.
CLI::Option* required(CLI::Option* option);

/// Replaces the default an option's help states, "(default: ...)", with `default_text`: each option states
/// its default once, there (e.g. `trace --csv`, whose default is standard output, not "not written").
CLI::Option* with_default(CLI::Option* option, const std::string& default_text);

/// A required positional argument; --help shows `value_name` after its name (FILE, DIR, TEXT). A FILE or DIR
/// refuses an empty value, as the options naming a file do (`--spec ""`); `-` there is a file of that name.
CLI::Option* add_positional(CLI::App& app, const std::string& name, std::string& target,
                            const std::string& description, const std::string& value_name = "TEXT");
/// One or more positional arguments (`report DIR...`), each as `add_positional` takes one.
CLI::Option* add_positional_list(CLI::App& app, const std::string& name, std::vector<std::string>& target,
                                 const std::string& description, const std::string& value_name);

/// Throws UsageError when more than one of `uses` (option name, writes standard output) is true:
/// standard output carries one document at a time.
void require_one_standard_output(const std::vector<std::pair<std::string, bool>>& uses);

}  // namespace calligraphy::cli
