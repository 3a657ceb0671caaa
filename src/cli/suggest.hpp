#pragma once
// "Did you mean": CLI11 2.1 (Debian 12) names an argument it cannot place but suggests nothing, so a
// mistyped command or option is named here together with the names the command knows that are close to
// it (Damerau-Levenshtein distance at most 2, or the one name it begins).
#include <string>
#include <vector>

#include "cli/app.hpp"

namespace calligraphy::cli {

/// The names among `known` that `typed` is likely a typo of: the only one `typed` begins, else those at
/// the smallest edit distance (insertion, deletion, substitution, swap of neighbours: 1 each) when it is
/// at most 2 and smaller than the name is long; at most 3, in the order of `known`.
std::vector<std::string> close_names(const std::string& typed, const std::vector<std::string>& known);

/// What went wrong with the arguments CLI11 left unplaced in `app` (its remaining()): the first unknown
/// option, or else, when `app` has commands, the first argument as an unknown command; each with the close
/// names ("unknown option '--guidence'; did you mean '--guidance'?"). Empty when nothing was left, or
/// only a value that is not an option where `app` has no commands (CLI11's message says that well).
std::string unknown_argument_message(const CLI::App& app);

}  // namespace calligraphy::cli
