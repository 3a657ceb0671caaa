#include "cli/suggest.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>

namespace calligraphy::cli {
namespace {

// Optimal string alignment distance (Damerau-Levenshtein without edits inside a swapped pair): a swap of
// two neighbouring characters, the commonest typo (trail for trial), counts as one edit.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// The name without its leading dashes: what is typed, so what must be long enough to be guessed at.
std::size_t letters(const std::string& name) {
  return name.size() - std::min(name.find_first_not_of('-'), name.size());
}

// '-' (standard output) and negative numbers are values, not options.
bool looks_like_option(const std::string& argument) {
  return argument.size() > 1 && argument[0] == '-' &&
         !std::isdigit(static_cast<unsigned char>(argument[1])) && argument[1] != '.';
}

std::vector<std::string> option_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
    for (const std::string& name : option->get_snames()) names.push_back("-" + name);
  }
  return names;
}

std::vector<std::string> command_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands(std::function<bool(const CLI::App*)>{})) {
    names.push_back(command->get_name());
  }
  return names;
}

// "; did you mean 'a', 'b' or 'c'?", or nothing.
std::string did_you_mean(const std::string& typed, const std::vector<std::string>& known) {
  const std::vector<std::string> close = close_names(typed, known);
  if (close.empty()) return "";
  std::string text = "; did you mean ";
  for (std::size_t i = 0; i < close.size(); ++i) {
    if (i > 0) text += i + 1 == close.size() ? " or " : ", ";
    text += "'" + close[i] + "'";
  }
  return text + "?";
}

}  // namespace

std::vector<std::string> close_names(const std::string& typed, const std::vector<std::string>& known) {
  constexpr std::size_t kMaxDistance = 2;
  constexpr std::size_t kMaxNames = 3;
  std::vector<std::string> begun;
  for (const std::string& name : known) {
    if (letters(typed) > 0 && name.size() > typed.size() && name.compare(0, typed.size(), typed) == 0) {
      begun.push_back(name);
    }
  }
  if (begun.size() == 1) return begun;
  std::vector<std::string> closest;
  std::size_t best = kMaxDistance + 1;
  for (const std::string& name : known) {
    const std::size_t distance = edit_distance(typed, name);
    // A short name is within 2 edits of too much ("-x" of "-h"): the edits must leave some of it.
    if (distance > kMaxDistance || distance >= letters(name) || distance > best) continue;
    if (distance < best) closest.clear();
    best = distance;
    if (closest.size() < kMaxNames && std::find(closest.begin(), closest.end(), name) == closest.end()) {
      closest.push_back(name);
    }
  }
  return closest;
}

std::string unknown_argument_message(const CLI::App& app) {
  const std::vector<std::string> left = app.remaining();
  // A mistyped option leaves its value behind too (`--guidence on`): the option is the mistake.
  for (const std::string& argument : left) {
    if (!looks_like_option(argument)) continue;
    const std::string name = argument.substr(0, argument.find('='));
    return "unknown option '" + name + "'" + did_you_mean(name, option_names(app));
  }
  const std::vector<std::string> commands = command_names(app);
  if (left.empty() || commands.empty()) return "";
  return "unknown command '" + left.front() + "'" + did_you_mean(left.front(), commands);
}

}  // namespace calligraphy::cli
