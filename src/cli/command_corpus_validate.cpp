// `calligraphy corpus validate --data DIR --cnchar FILE [--markdown FILE] [--json] [--threads N]`:
// per-stroke agreement of the typical-stroke classification with cnchar-order's letters
// (docs/classification.md is this command's --markdown output).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "cli/arguments.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "core/unicode.hpp"
#include "eval/cnchar_validation.hpp"

namespace calligraphy::cli {

int command_corpus_validate(const Args& all) {
  const Args args(all.begin() + 1, all.end());  // after "validate"
  const Arguments arguments(args, {"data", "cnchar", "markdown", "threads", "features"}, {"json"});
  if (!arguments.positionals().empty()) throw UsageError("corpus validate takes no positional arguments");
  const auto cnchar_path = arguments.option("cnchar");
  if (!cnchar_path)
    throw UsageError("corpus validate needs --cnchar FILE (scripts/fetch-cnchar-order.sh prints it)");
  std::ifstream in(*cnchar_path, std::ios::binary);
  if (!in) throw DataError(*cnchar_path + ": cannot read the cnchar-order file");
  std::stringstream text;
  text << in.rdbuf();
  const auto labels = parse_cnchar_orders(text.str(), *cnchar_path);

  const CharacterLibrary library = library_from(arguments);
  const double threads =
      arguments.number_or("threads", std::max(1u, std::min(2u, std::thread::hardware_concurrency())));
  if (threads < 1 || threads > 64) throw UsageError("--threads expects 1-64");
  const auto start = std::chrono::steady_clock::now();
  std::ofstream features;
  if (const auto path = arguments.option("features")) {
    features.open(*path, std::ios::binary);
    if (!features) throw DataError(*path + ": cannot write file");
  }
  const CncharValidation result =
      validate_against_cnchar(library, labels, FitOptions{}, static_cast<unsigned>(threads),
                              features.is_open() ? &features : nullptr);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::string data_description =
      arguments.option("data")
          ? "hanzi-writer-data 2.0.1 (" + std::to_string(library.characters().size()) + " characters)"
          : library.description();
  if (const auto path = arguments.option("markdown")) {
    write_file(*path, cnchar_validation_markdown(
                          result, data_description,
                          "cnchar-order 3.2.6 (" + std::to_string(labels.size()) + " characters)"));
  }
  if (arguments.flag("json")) {
    std::cout << cnchar_validation_json(result).dump(2) << "\n";
    return 0;
  }
  std::printf("cnchar labels: %zu characters; data: %s\n", result.labelled, data_description.c_str());
  std::printf(
      "compared %zu characters (%zu strokes); skipped %zu not in the data, %zu with other stroke counts\n",
      result.compared, result.strokes, result.missing, result.count_mismatch.size());
  std::printf("per-stroke agreement %.2f %% (%zu of %zu); characters fully agreeing %.2f %%\n",
              100.0 * result.agreement(), result.agreeing, result.strokes,
              result.compared ? 100.0 * static_cast<double>(result.characters_all_agree) /
                                    static_cast<double>(result.compared)
                              : 0.0);
  std::printf("fit and classify: %.2f s on %u thread(s)\n", seconds, static_cast<unsigned>(threads));
  return 0;
}

}  // namespace calligraphy::cli
