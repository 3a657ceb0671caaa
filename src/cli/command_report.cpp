// `calligraphy report DIR... --out report.html --csv TABLES`: one self-contained HTML page for the saved trials
// of one or many study sessions (study/session_reader.hpp, report/study_report_html.hpp), and the study as
// tidy tables (study/study_tables.hpp): TABLES/trials.csv and TABLES/strokes.csv.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/study/session_reader.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct ReportCommand {
  std::vector<std::string> folders;
  std::string out;
  std::string csv;  // a folder for trials.csv and strokes.csv
};

int run_report(const ReportCommand& command) {
  if (command.out.empty() && command.csv.empty()) throw UsageError("give --out FILE, --csv DIR or both");
  const auto start = std::chrono::steady_clock::now();
  // Every file of the session folders read (saved trial records among them) is an input: --out replaces none.
  FilePlan files;
  for (const std::string& folder : command.folders) add_saved_sessions(files, "DIR", folder);
  files.output("--out", command.out);
  const std::filesystem::path tables_folder(command.csv);
  if (!command.csv.empty()) {
    files.existing_output_folder("--csv", command.csv);
    files.output("--csv", (tables_folder / "trials.csv").string());
    files.output("--csv", (tables_folder / "strokes.csv").string());
  }
  std::vector<std::filesystem::path> roots(command.folders.begin(), command.folders.end());
  const auto elapsed = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (!command.csv.empty()) {
    const StudyTables tables = read_study_tables(roots);
    // Both tables or neither: a failure leaves the previous pair whole.
    const std::string trials_text = trials_csv(tables), strokes_text = strokes_csv(tables);
    const FileContent table_files[] = {{tables_folder / "trials.csv", trials_text},
                                       {tables_folder / "strokes.csv", strokes_text}};
    write_files_atomically(table_files);
    if (command.out != "-") {
      std::printf("%s: trials.csv (%zu rows), strokes.csv (%zu rows), %.1f s\n", command.csv.c_str(),
                  tables.trials.size(), tables.strokes.size(), elapsed());
    }
  }
  if (!command.out.empty()) {
    const StudyReport report = read_study_report(roots);
    const std::string page = study_report_html(report);
    write_output(command.out, page);
    if (command.out != "-") {
      std::printf("%s: %zu sessions, %zu trials, %.1f MB, %.1f s\n", command.out.c_str(),
                  report.sessions.size(), report.trials.size(), static_cast<double>(page.size()) / 1e6,
                  elapsed());
    }
  }
  return 0;
}

}  // namespace

void add_report_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<ReportCommand>();
  CLI::App* app = commands.add(root, "report", "Turn study sessions into one self-contained HTML page",
                               [command] { return run_report(*command); });
  app->add_option("DIR", command->folders,
                  "session folders, or folders holding them (e.g. a `session run --out` folder)")
      ->required()
      ->type_name("DIR");
  add_output_path(*app, "--out", command->out, "the HTML page", StandardOutput::allowed);
  add_output_folder(*app, "--csv", command->csv,
                    "an existing folder for the tidy tables trials.csv and strokes.csv (docs/experiments.md)",
                    "not written");
}

}  // namespace calligraphy::cli
