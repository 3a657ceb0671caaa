// `calligraphy corpus validate --cnchar FILE [--data DIR] [--markdown FILE] [--json] [--threads N]`:
// per-stroke agreement of the typical-stroke classification with cnchar-order's letters
// (docs/classification.md is this command's --markdown output).
#include <fmt/printf.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "eval/cnchar_validation.hpp"

namespace calligraphy::cli {
namespace {

struct ValidateCommand {
  LibraryOptions library;
  std::string cnchar;
  std::string markdown;
  bool json = false;
  std::int64_t threads = std::max(1u, std::min(2u, std::thread::hardware_concurrency()));
  std::string features;
};

std::string summary_text(const CncharValidation& result, const std::string& data_description, double seconds,
                         unsigned threads) {
  std::string out;
  out += fmt::sprintf("cnchar labels: %zu characters; data: %s\n", result.labelled, data_description.c_str());
  out += fmt::sprintf(
      "compared %zu characters (%zu strokes); skipped %zu not in the data, %zu with other stroke counts\n",
      result.compared, result.strokes, result.missing, result.count_mismatch.size());
  out += fmt::sprintf("per-stroke agreement %.2f %% (%zu of %zu); characters fully agreeing %.2f %%\n",
                      100.0 * result.agreement(), result.agreeing, result.strokes,
                      result.compared ? 100.0 * static_cast<double>(result.characters_all_agree) /
                                            static_cast<double>(result.compared)
                                      : 0.0);
  out += fmt::sprintf("fit and classify: %.2f s on %u thread(s)\n", seconds, threads);
  return out;
}

int run_validate(const ValidateCommand& command) {
  require_one_standard_output({{"--json", command.json}, {"--markdown -", command.markdown == "-"}});
  FilePlan files;
  files.input("--cnchar", command.cnchar);
  add_library_inputs(files, command.library);
  files.output("--features", command.features);
  files.output("--markdown", command.markdown);
  const auto labels = parse_cnchar_orders(
      read_input_file(command.cnchar, "cnchar-order's cnchar.order.min.js"), command.cnchar);
  const CharacterLibrary library = library_from(command.library);
  // Listing the folder first: one without character files is an error naming it (DataError).
  const std::string data_description =
      command.library.data_folder.empty()
          ? library.description()
          : "hanzi-writer-data 2.0.1 (" + std::to_string(library.characters().size()) + " characters)";
  const auto threads = static_cast<unsigned>(command.threads);
  const auto start = std::chrono::steady_clock::now();
  std::ostringstream features;
  const CncharValidation result = validate_against_cnchar(library, labels, FitOptions{}, threads,
                                                          command.features.empty() ? nullptr : &features);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result.compared == 0) {  // an agreement over nothing is no result
    throw DataError("nothing to compare: of the " + std::to_string(result.labelled) + " characters " +
                    command.cnchar + " labels, " + std::to_string(result.missing) + " are not in the data (" +
                    library.description() + ") and " + std::to_string(result.count_mismatch.size()) +
                    " have other stroke counts there");
  }
  if (!command.features.empty()) write_output(command.features, features.str());
  if (!command.markdown.empty()) {
    write_output(
        command.markdown,
        cnchar_validation_markdown(result, data_description,
                                   "cnchar-order 3.2.6 (" + std::to_string(labels.size()) + " characters)"));
  }
  if (command.json) {
    write_standard_output(json_text(cnchar_validation_json(result), 2) + "\n");
  } else if (command.markdown != "-") {
    write_standard_output(summary_text(result, data_description, seconds, threads));
  }
  return 0;
}

}  // namespace

void add_corpus_validate_command(CLI::App& corpus, Commands& commands) {
  auto command = std::make_shared<ValidateCommand>();
  CLI::App* app = commands.add(corpus, "validate",
                               "Per-stroke agreement of the typical-stroke classification with cnchar-order",
                               [command] { return run_validate(*command); });
  required(add_input_path(
      *app, "--cnchar", command->cnchar, "FILE",
      "cnchar-order's cnchar.order.min.js (scripts/fetch-cnchar-order.sh prints its path)", ""));
  add_library_options(*app, command->library, false);
  add_output_path(*app, "--markdown", command->markdown,
                  "write the report as Markdown (docs/classification.md)", StandardOutput::allowed);
  add_flag(*app, "--json", command->json, "print the result as JSON");
  add_integer(*app, "--threads", command->threads, "N", "threads that fit and classify", 1, 64,
              "one per CPU, at most 2; " + std::to_string(command->threads) + " here");
  add_output_path(*app, "--features", command->features, "write each stroke's classification features (CSV)",
                  StandardOutput::refused);
}

}  // namespace calligraphy::cli
