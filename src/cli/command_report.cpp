// `calligraphy report DIR... --out trials.html --csv TABLES`: the per-trial pages of one or many study
// sessions (study/session_reader.hpp, report/study_report_html.hpp): an index page and one page per session
// in trials_files/SUBJECT/SESSION.html; and the study as tidy tables (study/study_tables.hpp):
// TABLES/trials.csv and TABLES/strokes.csv.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iterator>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/worker_threads.hpp"
#include "calligraphy/report/study_report_html.hpp"
#include "calligraphy/study/session_reader.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace fs = std::filesystem;
namespace {

struct ReportCommand {
  std::vector<std::string> folders;
  std::string out;
  std::string csv;        // a folder for trials.csv and strokes.csv
  std::int64_t jobs = 0;  // 0: every core
};

// Each session's page, built as its trials are read and written whole (the temporary of its file in the
// report's set) before the next session is read: memory holds one session's page and one trial per thread.
// The folders a report makes for its pages (FILE_files/ and a folder per subject), made before the pages are
// read; unless keep() is called, each one made is removed again (rmdir: only while empty, as nothing was
// written in it), so a report that fails leaves no folder of its own, as it leaves no file; a stop signal
// removes them too (register_made_folder). A folder that
// another process made first is not this report's, and is left to it.
class MadeFolders {
 public:
  MadeFolders() = default;
  MadeFolders(const MadeFolders&) = delete;
  MadeFolders& operator=(const MadeFolders&) = delete;
  ~MadeFolders() {
    for (auto made = made_.rbegin(); made != made_.rend(); ++made) {
      if (!kept_) ::rmdir(made->folder.c_str());
      release_made_folder(made->signal_slot);
    }
  }

  // Thread-safe: the pages' threads make their folders again when they are gone (write_page).
  void make(const fs::path& folder) {
    const std::lock_guard<std::mutex> hold(mutex_);
    make_locked(folder);
  }
  void keep() noexcept { kept_ = true; }

 private:
  // A parent removed between its check and the folder's creation (by another report that failed, as in
  // write_page) is made again.
  void make_locked(const fs::path& folder) {
    for (int attempt = 1;; ++attempt) {
      std::error_code error;
      if (folder.empty() || fs::is_directory(folder, error)) return;
      make_locked(folder.parent_path());
      // Registered before it exists, so that a stop signal at any moment removes it (guard_output_files).
      const int signal_slot = register_made_folder(folder);
      if (fs::create_directory(folder, error)) {
        made_.push_back({folder, signal_slot});
        return;
      }
      release_made_folder(signal_slot);
      if (!error) return;  // made by another process meanwhile: not this report's
      if (attempt == 3 || error != std::errc::no_such_file_or_directory)
        throw DataError(folder.string() + ": cannot create the folder: " + error.message());
    }
  }

  struct Made {
    fs::path folder;
    int signal_slot = -1;  // its registration for the stop signals' removal
  };
  std::mutex mutex_;
  std::vector<Made> made_;
  bool kept_ = false;
};

// With `tables`, each session's rows of the tidy tables are read from the same parse of its records.
class PagesWriter {
 public:
  PagesWriter(const StudyReportSessions& sessions, const std::vector<fs::path>& page_files,
              std::string index_href)
      : study(sessions), pages(page_files), index_href_from_page(std::move(index_href)) {}

  const StudyReportSessions& study;
  const std::vector<fs::path>& pages;
  std::string index_href_from_page;
  std::atomic<std::size_t> trials{0};
  std::atomic<std::uintmax_t> bytes{0};
  std::vector<StudyTables>* tables = nullptr;  // one per session, when the tables are wanted too
  OutputSet* files = nullptr;                  // the report's files, replaced together at the end
  MadeFolders* folders = nullptr;              // the pages' folders

  void write_page(std::size_t i) {
    const ReportedSession& session = study.sessions[i];
    SessionPageHtml page(session.shown, study.index.title, index_href_from_page);
    read_session_trials(
        session, [&page](const ReportTrial& trial) { page.add(trial); },
        tables != nullptr ? &(*tables)[i] : nullptr);
    trials += page.trials();
    const std::string text = page.finish();
    bytes += text.size();
    // Another report into the same folder that failed removes the page folders it made while they are empty,
    // which may be before this report's first page is in one of them: a folder gone is made again.
    const fs::path folder = pages[i].parent_path();
    for (int attempt = 1;; ++attempt) {
      folders->make(folder);
      try {
        files->add(pages[i], text);
        return;
      } catch (const DataError&) {
        std::error_code error;
        if (attempt == 3 || fs::is_directory(folder, error)) throw;
      }
    }
  }
};

int run_report(const ReportCommand& command) {
  if (command.out.empty() && command.csv.empty()) throw UsageError("give --out FILE, --csv DIR or both");
  const auto start = std::chrono::steady_clock::now();
  // Every file of the session folders read (saved trial records among them) is an input: --out replaces none.
  FilePlan files;
  for (const std::string& folder : command.folders) add_saved_sessions(files, "DIR", folder);
  files.set_output("--out", command.out);
  if (!command.out.empty()) {
    // The pages go in NAME_files/ beside the index page: beside a device or FIFO, written in place, that
    // would be a folder in /dev (`--out /dev/null`). So, as '-', it is refused: the pages need a folder.
    const FilePlan::Identity index = identify_file("--out", command.out);
    if (index.exists && !index.regular && !index.folder) {
      throw UsageError("--out " + command.out +
                       ": not a regular file (a device, FIFO or socket): the session pages go in a folder "
                       "beside the index page; give a file name");
    }
  }
  const fs::path tables_folder(command.csv);
  if (!command.csv.empty()) {
    files.existing_output_folder("--csv", command.csv);
    files.set_output("--csv", (tables_folder / "trials.csv").string());
    files.set_output("--csv", (tables_folder / "strokes.csv").string());
  }
  std::vector<fs::path> roots(command.folders.begin(), command.folders.end());
  const auto elapsed = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // Everything this run writes (the tables, the pages, the index) is one set: replaced together at the end,
  // or, on any failure, none of it, the earlier report and tables left whole.
  // Declared before the set: on a failure the set's temporaries in the page folders go first, then the
  // folders.
  MadeFolders page_folders;
  OutputSet report_files;
  std::string tables_line;
  const auto add_tables = [&](const StudyTables& tables) {
    report_files.add(tables_folder / "trials.csv", trials_csv(tables));
    report_files.add(tables_folder / "strokes.csv", strokes_csv(tables));
    char line[256];
    std::snprintf(line, sizeof line, "trials.csv (%zu rows), strokes.csv (%zu rows)", tables.trials.size(),
                  tables.strokes.size());
    tables_line = line;
  };
  // The tables alone read the records only; with the pages they come from the pages' read of each record.
  if (!command.csv.empty() && command.out.empty())
    add_tables(read_study_tables(roots, static_cast<unsigned>(command.jobs)));
  std::string pages_line;
  if (!command.out.empty()) {
    const StudyReportSessions study = list_report_sessions(roots);
    const fs::path index_path(command.out);
    const std::string index_name = index_path.filename().string();
    // The pages are outputs too: none may be a file the command reads.
    const fs::path pages_folder = index_path.parent_path() / session_pages_folder(index_name);
    files.set_output_folder("--out", pages_folder.string());
    std::vector<fs::path> pages;
    for (const ReportedSession& s : study.sessions) {
      pages.push_back(index_path.parent_path() /
                      session_page_path(index_name, s.shown.subject, s.shown.session));
      files.set_output_folder("--out", pages.back().parent_path().string());
      files.set_output("--out", pages.back().string());
    }
    for (const fs::path& page : pages) page_folders.make(page.parent_path());
    PagesWriter writer(study, pages, "../../" + index_name);
    writer.files = &report_files;
    writer.folders = &page_folders;
    std::vector<StudyTables> session_tables(command.csv.empty() ? 0 : study.sessions.size());
    if (!command.csv.empty()) writer.tables = &session_tables;
    for_each_item(study.sessions.size(), static_cast<std::size_t>(command.jobs),
                  [&writer](std::size_t i) { writer.write_page(i); });
    if (!command.csv.empty()) {  // the sessions' rows in the sessions' order, as read_study_tables gives them
      StudyTables tables;
      for (StudyTables& rows : session_tables) {
        std::move(rows.trials.begin(), rows.trials.end(), std::back_inserter(tables.trials));
        std::move(rows.strokes.begin(), rows.strokes.end(), std::back_inserter(tables.strokes));
        rows = StudyTables{};
      }
      add_tables(tables);
    }
    const std::string index = study_index_html(study.index, index_name);
    report_files.add(index_path, index);
    char line[512];
    std::snprintf(line, sizeof line, "%zu sessions, %zu trials, %zu pages in %s (%.1f MB)",
                  study.sessions.size(), writer.trials.load(), pages.size(),
                  printable_name(pages_folder.string()).c_str(),
                  static_cast<double>(writer.bytes.load() + index.size()) / 1e6);
    pages_line = line;
  }
  report_files.commit();
  page_folders.keep();
  if (!tables_line.empty())
    std::printf("%s: %s, %.1f s\n", printable_name(command.csv).c_str(), tables_line.c_str(), elapsed());
  if (!pages_line.empty())
    std::printf("%s: %s, %.1f s\n", printable_name(command.out).c_str(), pages_line.c_str(), elapsed());
  return 0;
}

}  // namespace

void add_report_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<ReportCommand>();
  CLI::App* app = commands.add(root, "report", "Per-trial pages and tidy tables of study sessions",
                               [command] { return run_report(*command); });
  add_positional_list(*app, "DIR", command->folders,
                      "session folders, or folders holding them (e.g. a `session run --out` folder)", "DIR");
  add_output_path(*app, "--out", command->out,
                  "the index page; each session's page goes to NAME_files/SUBJECT/SESSION.html beside it",
                  StandardOutput::refused);
  add_output_folder(*app, "--csv", command->csv,
                    "an existing folder for the tidy tables trials.csv and strokes.csv (docs/experiments.md)",
                    "not written");
  add_integer(*app, "--jobs", command->jobs, "N", "threads reading sessions", 1, 256, "every core");
}

}  // namespace calligraphy::cli
