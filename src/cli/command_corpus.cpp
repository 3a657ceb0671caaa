// `calligraphy corpus build|stats|fidelity`: the whole hanzi-writer-data corpus modelled into a compact
// store (docs/corpus.md), its statistics, and the fidelity/size trade over fitting tolerances.
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"
#include "eval/corpus_fidelity.hpp"
#include "eval/corpus_fit.hpp"
#include "eval/corpus_report.hpp"

namespace calligraphy::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Options of the commands that fit the whole corpus.
struct CorpusFitCommand {
  std::string data_folder;
  std::string steps = std::to_string(CorpusStoreOptions{}.steps_per_unit);
  std::int64_t threads = default_corpus_threads();
};

void add_fit_options(CLI::App& app, CorpusFitCommand& command) {
  add_input_path(app, "--data", command.data_folder, "DIR", "the hanzi-writer-data folder",
                 "the folder scripts/fetch-hanzi-writer-data.sh fills");
  add_choice(app, "--steps", command.steps, {"1", "2", "4", "8", "16"},
             "quantisation of control points [steps per data unit]");
  add_integer(app, "--threads", command.threads, "N", "threads that fit characters", 1, 256,
              "one per CPU, " + std::to_string(default_corpus_threads()) + " here");
}

std::filesystem::path corpus_folder(const CorpusFitCommand& command) {
  if (!command.data_folder.empty()) return command.data_folder;
  if (const auto fetched = complete_fetched_corpus_folder()) return *fetched;
  throw UsageError("--data: no hanzi-writer-data folder: run scripts/fetch-hanzi-writer-data.sh (it fills " +
                   fetched_corpus_folder().string() + ") or pass --data DIR");
}

struct BuildCommand {
  CorpusFitCommand fit;
  std::string out;
  double tolerance = FitOptions{}.tolerance;
  std::string medians = "on";
  std::string outlines = "on";
};

// Each character's outline paths as its file gives them, in the order of `characters`; none for a file
// without a readable `strokes` array (the character is still stored, drawn without outlines).
std::vector<std::vector<std::string>> outline_paths(const CharacterLibrary& library,
                                                    const std::vector<Character>& characters) {
  std::vector<std::vector<std::string>> paths(characters.size());
  for (std::size_t i = 0; i < characters.size(); ++i) {
    try {
      paths[i] = library.load_outline_paths(characters[i].code_point);
      if (paths[i].size() != characters[i].strokes.size()) paths[i].clear();
    } catch (const DataError&) {
    }
  }
  return paths;
}

int run_build(const BuildCommand& command, bool verbose) {
  const std::filesystem::path folder = corpus_folder(command.fit);
  FilePlan files;
  files.input_folder("--data", folder.string());
  files.output("--out", command.out);
  const CharacterLibrary library = CharacterLibrary::from_directory(folder);
  FitOptions fit_options;
  fit_options.tolerance = command.tolerance;
  CorpusStoreOptions store_options;
  store_options.steps_per_unit = std::stoi(command.fit.steps);
  store_options.fit_tolerance = fit_options.tolerance;
  store_options.medians = command.medians == "on";
  store_options.outlines = command.outlines == "on";

  const auto start = Clock::now();
  CorpusFit fit =
      fit_corpus(library, fit_options, static_cast<unsigned>(command.fit.threads), "fitting", verbose);
  drop_unstorable(fit, store_options);  // listed as not modelled; the store holds the others
  if (fit.characters.empty()) {         // a store of nothing would replace an earlier store with nothing
    throw DataError(folder.string() + ": none of its " + std::to_string(fit.failures.size()) +
                    " character files could be modelled, so " + command.out + " is not written; the first: " +
                    (fit.failures.empty() ? std::string("none") : fit.failures.front().reason));
  }
  const auto write_start = Clock::now();
  // Encoded in memory and then written whole: an earlier store survives any failure to write this one.
  const std::vector<std::vector<std::string>> outlines = store_options.outlines
                                                             ? outline_paths(library, fit.characters)
                                                             : std::vector<std::vector<std::string>>{};
  const std::vector<std::uint8_t> bytes = encode_corpus_store(fit.characters, store_options, outlines);
  write_output(command.out, bytes);
  const CorpusBuildTimes times{seconds_since(start), seconds_since(write_start)};
  write_standard_output(
      corpus_build_text(command.out, library.description(), fit, store_options, bytes.size(), times));
  if (fit.failures.empty()) return 0;
  // The exit status 1 said in the command's error line, as every failure is: how many, and the first.
  print_error_line(
      "calligraphy corpus build", "error",
      std::to_string(fit.failures.size()) + " of the character files could not be modelled (" + command.out +
          " holds the others; each is listed on standard output), the first: " + fit.failures.front().reason);
  return 1;
}

struct StatsCommand {
  std::string store;
  bool json = false;
};

int run_stats(const StatsCommand& command) {
  const CorpusStore store = CorpusStore::open(command.store);
  const CorpusStoreStats stats = corpus_store_stats(store);
  write_standard_output(command.json ? corpus_stats_json(store, stats) : corpus_stats_text(store, stats));
  // The statistics on standard output (the JSON lists the errors too); each bad record an error line.
  for (const std::string& error : stats.errors) print_error_line("calligraphy corpus stats", "error", error);
  return stats.errors.empty() ? 0 : 1;
}

struct FidelityCommand {
  CorpusFitCommand fit;
  std::vector<double> tolerances{2.0, 5.0, 10.0, 20.0};
  std::string markdown;
};

int run_fidelity(const FidelityCommand& command, bool verbose) {
  const std::filesystem::path folder = corpus_folder(command.fit);
  FilePlan files;
  files.input_folder("--data", folder.string());
  files.output("--markdown", command.markdown);
  const CharacterLibrary library = CharacterLibrary::from_directory(folder);
  const int steps = std::stoi(command.fit.steps);
  const std::vector<FidelityRow> rows = measure_corpus_fidelity(
      library, command.tolerances, steps, static_cast<unsigned>(command.fit.threads), verbose);
  const std::string table = corpus_fidelity_markdown(rows, steps);
  write_standard_output(table);
  if (!command.markdown.empty() && command.markdown != "-") write_output(command.markdown, table);
  return 0;
}

bool positive(double value) { return value > 0.0; }

}  // namespace

void add_corpus_build_command(CLI::App& corpus, Commands& commands) {
  auto command = std::make_shared<BuildCommand>();
  CLI::App* app =
      commands.add(corpus, "build", "Model every character of hanzi-writer-data into a compact store",
                   [command, &commands] { return run_build(*command, commands.verbose()); });
  required(add_output_path(*app, "--out", command->out, "the store to write", StandardOutput::refused));
  add_number(*app, "--tolerance", command->tolerance, "UNITS",
             "largest deviation of the fitted elements from the median [data units, 1024 per character], > 0",
             "a number of data units > 0", positive);
  add_choice(*app, "--medians", command->medians, {"on", "off"},
             "store the strokes' medians too (format 1.1; off: a 1.0 store of the models only)");
  add_choice(
      *app, "--outlines", command->outlines, {"on", "off"},
      "store the strokes' outlines too, for drawing (format 1.2; off: none, the window draws the medians)");
  add_fit_options(*app, command->fit);
}

void add_corpus_stats_command(CLI::App& corpus, Commands& commands) {
  auto command = std::make_shared<StatsCommand>();
  CLI::App* app =
      commands.add(corpus, "stats",
                   "Characters, strokes, elements, bytes, typical-stroke histogram and checksums of a store",
                   [command] { return run_stats(*command); });
  add_positional(*app, "FILE", command->store, "the corpus store", "FILE");
  add_flag(*app, "--json", command->json, "print the statistics as JSON");
}

void add_corpus_fidelity_command(CLI::App& corpus, Commands& commands) {
  auto command = std::make_shared<FidelityCommand>();
  CLI::App* app = commands.add(
      corpus, "fidelity", "Elements, bytes and deviation from the medians per fitting tolerance (Markdown)",
      [command, &commands] { return run_fidelity(*command, commands.verbose()); });
  add_number_list(*app, "--tolerances", command->tolerances, "LIST",
                  "fitting tolerances to compare [data units], each > 0", "numbers > 0", positive);
  add_output_path(*app, "--markdown", command->markdown, "also write the table (printed anyway) to a file",
                  StandardOutput::allowed);
  add_fit_options(*app, command->fit);
}

}  // namespace calligraphy::cli
