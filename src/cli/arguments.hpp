#pragma once
// A small command-line parser: positionals, `--name value` options and `--flag` switches, with
// errors that name the offending argument.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cli/commands.hpp"

namespace calligraphy::cli {

class Arguments {
 public:
  /// `options` take a value, `flags` do not. Throws UsageError on unknown or incomplete options.
  Arguments(const Args& args, const std::set<std::string>& options, const std::set<std::string>& flags);

  [[nodiscard]] const std::vector<std::string>& positionals() const { return positionals_; }
  [[nodiscard]] bool flag(const std::string& name) const { return flags_.count(name) != 0; }
  [[nodiscard]] std::optional<std::string> option(const std::string& name) const;
  [[nodiscard]] std::string option_or(const std::string& name, const std::string& fallback) const;
  /// The option as a number; throws UsageError naming it when it is not one.
  [[nodiscard]] double number_or(const std::string& name, double fallback) const;
  /// One of `choices`; throws UsageError otherwise.
  [[nodiscard]] std::string choice_or(const std::string& name, const std::vector<std::string>& choices,
                                      const std::string& fallback) const;

 private:
  std::vector<std::string> positionals_;
  std::map<std::string, std::string> options_;
  std::set<std::string> flags_;
};

}  // namespace calligraphy::cli
