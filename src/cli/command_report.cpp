// `calligraphy report DIR... --out report.html`: one self-contained HTML page for the saved trials of
// one or many study sessions (study/session_reader.hpp, report/study_report_html.hpp).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/study/session_reader.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct ReportCommand {
  std::vector<std::string> folders;
  std::string out;
};

int run_report(const ReportCommand& command) {
  const auto start = std::chrono::steady_clock::now();
  // Every file of the session folders read (saved trial records among them) is an input: --out replaces none.
  FilePlan files;
  for (const std::string& folder : command.folders) add_saved_sessions(files, "DIR", folder);
  files.output("--out", command.out);
  std::vector<std::filesystem::path> roots(command.folders.begin(), command.folders.end());
  const StudyReport report = read_study_report(roots);
  const std::string page = study_report_html(report);
  write_output(command.out, page);
  if (command.out != "-") {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s: %zu sessions, %zu trials, %.1f MB, %.1f s\n", command.out.c_str(),
                report.sessions.size(), report.trials.size(), static_cast<double>(page.size()) / 1e6,
                seconds);
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
  required(add_output_path(*app, "--out", command->out, "the HTML page", StandardOutput::allowed));
}

}  // namespace calligraphy::cli
