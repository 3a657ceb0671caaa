#include "cli/arguments.hpp"

#include <cmath>
#include <stdexcept>

namespace calligraphy::cli {

Arguments::Arguments(const Args& args, const std::set<std::string>& options, const std::set<std::string>& flags) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.rfind("--", 0) != 0) {
      positionals_.push_back(a);
      continue;
    }
    const std::string name = a.substr(2);
    if (flags.count(name) != 0) {
      flags_.insert(name);
    } else if (options.count(name) != 0) {
      if (i + 1 >= args.size()) throw UsageError("option " + a + " needs a value");
      options_[name] = args[++i];
    } else {
      throw UsageError("unknown option " + a);
    }
  }
}

std::optional<std::string> Arguments::option(const std::string& name) const {
  const auto it = options_.find(name);
  if (it == options_.end()) return std::nullopt;
  return it->second;
}

std::string Arguments::option_or(const std::string& name, const std::string& fallback) const {
  return option(name).value_or(fallback);
}

double Arguments::number_or(const std::string& name, double fallback) const {
  const auto value = option(name);
  if (!value) return fallback;
  try {
    std::size_t used = 0;
    const double x = std::stod(*value, &used);
    if (used != value->size() || !std::isfinite(x)) throw std::invalid_argument("trailing");
    return x;
  } catch (const std::exception&) {
    throw UsageError("--" + name + " expects a number, got '" + *value + "'");
  }
}

std::string Arguments::choice_or(const std::string& name, const std::vector<std::string>& choices,
                                 const std::string& fallback) const {
  const std::string value = option_or(name, fallback);
  for (const auto& c : choices) {
    if (c == value) return value;
  }
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : "|") + c;
  throw UsageError("--" + name + " expects " + list + ", got '" + value + "'");
}

}  // namespace calligraphy::cli
