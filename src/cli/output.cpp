#include "cli/output.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <mutex>
#include <set>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

namespace {

// Every file a FilePlan of this process checked as an output, absolute and normal: the only files
// write_output and OutputSet write.
struct PlannedOutputs {
  std::mutex mutex;
  std::set<std::filesystem::path> paths;
};
PlannedOutputs& planned_outputs() {
  static PlannedOutputs planned;
  return planned;
}

std::filesystem::path normal_path(const std::filesystem::path& path) {
  return std::filesystem::absolute(path).lexically_normal();
}

void note_planned(const std::string& path) {
  PlannedOutputs& planned = planned_outputs();
  const std::lock_guard lock(planned.mutex);
  planned.paths.insert(normal_path(path));
}

void require_planned(const std::filesystem::path& path) {
  PlannedOutputs& planned = planned_outputs();
  const std::lock_guard lock(planned.mutex);
  if (planned.paths.count(normal_path(path)) == 0) {
    throw StateError(path.string() + ": written without being checked as an output first (FilePlan::output)");
  }
}

}  // namespace

void write_standard_output(std::string_view text) {
  std::cout.flush();  // keep the order of anything written through std::cout before
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0) {
    throw DataError(std::string("standard output: cannot write: ") + std::strerror(errno));
  }
}

void write_output(const std::string& path, std::string_view text) {
  if (path == "-") {
    write_standard_output(text);
  } else {
    require_planned(path);
    write_file_atomically(path, text);
  }
}

void write_output(const std::string& path, std::span<const std::uint8_t> bytes) {
  write_output(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void OutputSet::add(const std::filesystem::path& path, std::string_view content) {
  require_planned(path);
  set_.add(path, content);
}

void OutputSet::commit() { set_.commit(); }

std::string read_input_file(const std::string& path, const std::string& what) {
  std::optional<std::string> text = read_file_for_update(path);
  if (!text) throw DataError(path + ": not a regular file that exists (expected " + what + ")");
  return std::move(*text);
}

void print_error_line(std::string_view command, std::string_view kind, std::string_view message) {
  const std::string line = printable_one_line(command, 200) + ": " + printable_one_line(kind, 100) + ": " +
                           printable_one_line(message) + "\n";
  std::fputs(line.c_str(), stderr);
}

std::string printable_name(std::string_view text) {
  return printable_one_line(text, std::numeric_limits<std::size_t>::max() / 2);
}

int finish_standard_output(int status, const std::string& command) {
  errno = 0;
  std::cout.flush();  // synchronised with stdio: this flushes stdout, and may be where a failure shows
  const bool flushed = std::fflush(stdout) == 0;
  const int error = errno;  // a successful flush leaves errno as the first failure set it
  if (flushed && !std::ferror(stdout) && std::cout.good()) return status;
  if (status != 0) return status;  // the failure was reported already
  print_error_line(command, "error",
                   std::string("standard output: cannot write") + (error ? ": " : "") +
                       (error ? std::strerror(error) : ""));
  return 1;
}

namespace {

namespace fs = std::filesystem;

std::string named(const std::string& what, const std::string& path) { return what + " " + path; }

// A relative path is resolved against the working directory, which may have been removed under the process
// (getcwd fails): an error naming the option and the path, as a missing folder is.
fs::path absolute_path(const std::string& what, const std::string& path, const fs::path& relative) {
  std::error_code error;
  fs::path absolute = fs::absolute(relative, error);
  if (error) {
    throw DataError(named(what, path) +
                    ": cannot resolve it against the working directory: " + error.message());
  }
  return absolute;
}

bool same_file(const FilePlan::Identity& a, const FilePlan::Identity& b) {
  if (a.exists != b.exists) return false;
  return a.exists ? a.device == b.device && a.inode == b.inode : a.path == b.path;
}

FilePlan::Identity identity_of(const struct stat& status, const fs::path& path) {
  FilePlan::Identity identity;
  identity.exists = true;
  identity.regular = S_ISREG(status.st_mode);
  identity.folder = S_ISDIR(status.st_mode);
  identity.device = static_cast<unsigned long long>(status.st_dev);
  identity.inode = static_cast<unsigned long long>(status.st_ino);
  std::error_code error;
  const fs::path canonical = fs::canonical(path, error);
  identity.path = (error ? path : canonical).string();
  return identity;
}

// A folder files are created in: it must be one, and the command must be allowed to add to it.
void require_writable_folder(const std::string& what, const std::string& path, const fs::path& folder) {
  struct stat status {};
  if (::stat(folder.c_str(), &status) != 0) {
    const int error = errno;
    throw DataError(named(what, path) + ": the folder " + folder.string() + " " +
                    (error == ENOENT ? std::string("does not exist") : std::string(std::strerror(error))));
  }
  if (!S_ISDIR(status.st_mode)) {
    throw DataError(named(what, path) + ": " + folder.string() + " is not a folder");
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw DataError(named(what, path) + ": the folder " + folder.string() +
                    " is not writable: " + std::strerror(errno));
  }
}

fs::path folder_of(const fs::path& file) {
  const fs::path absolute = fs::absolute(file);
  return absolute.parent_path();
}

}  // namespace

FilePlan::Identity identify_file(const std::string& what, const std::string& path) {
  fs::path target;
  try {
    target = written_path(path);
  } catch (const DataError& e) {
    throw DataError(what + " " + e.what());
  }
  // Resolved first: a relative input or output once the working directory was removed is refused, as
  // docs/cli.md says (the kernel may still resolve "../x" from the removed folder, but no path can name what
  // was read).
  const fs::path absolute = absolute_path(what, path, target);
  struct stat status {};
  if (::stat(target.c_str(), &status) == 0) return identity_of(status, target);
  if (errno != ENOENT && errno != ENOTDIR) {
    throw DataError(named(what, path) + ": cannot examine: " + std::strerror(errno));
  }
  FilePlan::Identity identity;  // not there yet: the resolved folder and the name
  std::error_code error;
  const fs::path folder = fs::weakly_canonical(absolute.parent_path(), error);
  identity.path = ((error ? absolute.parent_path() : folder) / absolute.filename()).string();
  return identity;
}

void FilePlan::add_input(const std::string& what, const std::string& given, const Identity& identity) {
  inputs_.push_back({what, given, identity});
}

void FilePlan::input(const std::string& what, const std::string& path) {
  if (path.empty() || path == "-") return;
  add_input(named(what, path), path, identify_file(what, path));
}

void FilePlan::input_folder(const std::string& what, const std::string& path) {
  if (path.empty()) return;
  const Identity folder = identify_file(what, path);
  add_input(named(what, path), path, folder);
  if (!folder.exists || !folder.folder) return;  // the reader names what is missing
  std::error_code error;
  fs::recursive_directory_iterator it(path, fs::directory_options::skip_permission_denied, error);
  for (; !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    struct stat status {};
    if (::stat(it->path().c_str(), &status) == 0 && S_ISREG(status.st_mode)) {
      add_input(it->path().string() + ", a file under " + named(what, path), it->path().string(),
                identity_of(status, it->path()));
    }
  }
}

void add_saved_sessions(FilePlan& plan, const std::string& what, const std::string& root) {
  std::error_code error;
  if (root.empty() || !fs::is_directory(root, error)) return;
  std::vector<fs::path> sessions;
  try {
    sessions = find_session_folders(root);
  } catch (const DataError&) {
    return;  // the reader lists the folder again and names what is wrong
  }
  for (const fs::path& session : sessions) plan.input_folder(what, session.string());
}

void FilePlan::output(const std::string& what, const std::string& path) {
  if (path.empty() || path == "-") return;
  const Identity identity = identify_file(what, path);
  if (identity.folder) throw DataError(named(what, path) + ": is a folder, not a file");
  if (!identity.exists &&
      (path.back() == '/' || fs::path(path).filename() == ".." || fs::path(path).filename() == ".")) {
    throw DataError(named(what, path) + ": names a folder (it ends in '/', '.' or '..'), not a file");
  }
  if (identity.exists && !identity.regular) {  // a device or FIFO: written in place, never replaced
    note_planned(path);
    return;
  }
  for (const Entry& input : inputs_) {
    if (!same_file(identity, input.identity)) continue;
    throw UsageError(named(what, path) + " is the same file as " + input.what + " (" + identity.path +
                     "), which this command reads: refused, nothing written");
  }
  for (const Entry& output : outputs_) {
    if (!same_file(identity, output.identity)) continue;
    throw UsageError(named(what, path) + " and " + named(output.what, output.given) + " are the same file (" +
                     identity.path + "): one output would overwrite the other; nothing written");
  }
  if (identity.exists && ::access(identity.path.c_str(), W_OK) != 0) {
    throw DataError(named(what, path) + ": cannot write: " + std::strerror(errno));
  }
  // A file under a folder this command makes files and folders in (--session, --out's pages) may be in a
  // subfolder that does not exist yet (a subject who joined since the last report): the command makes it, and
  // output_folder checked the nearest folder that exists. A subfolder that exists must be writable.
  const fs::path folder = folder_of(identity.path).lexically_normal();
  const bool in_output_folder =
      std::any_of(output_folders_.begin(), output_folders_.end(), [&](const fs::path& made) {
        const fs::path relative = folder.lexically_relative(made);
        return !relative.empty() && *relative.begin() != "..";
      });
  std::error_code error;
  if (!in_output_folder || fs::exists(folder, error)) require_writable_folder(what, path, folder);
  outputs_.push_back({what, path, identity});
  note_planned(path);
}

void FilePlan::set_output(const std::string& what, const std::string& path) {
  output(what, path);
  struct stat status {};
  if (!path.empty() && path != "-" && ::lstat(path.c_str(), &status) == 0 && S_ISLNK(status.st_mode)) {
    throw UsageError(named(what, path) +
                     " is a symbolic link: the files of a set are written only in their own folders, never "
                     "through a link; remove it, nothing written");
  }
}

void FilePlan::output_folder(const std::string& what, const std::string& path) {
  if (path.empty()) return;
  const fs::path absolute = absolute_path(what, path, path);
  fs::path folder = absolute;
  struct stat status {};
  while (::stat(folder.c_str(), &status) != 0) {  // the nearest folder that exists is the one written in
    if (errno != ENOENT) throw DataError(named(what, path) + ": cannot examine: " + std::strerror(errno));
    if (folder == folder.root_path()) break;
    folder = folder.parent_path();
  }
  if (folder == absolute && !S_ISDIR(status.st_mode)) {
    throw DataError(named(what, path) + ": is not a folder");
  }
  require_writable_folder(what, path, folder);
  output_folders_.push_back(absolute.lexically_normal());
}

void FilePlan::set_output_folder(const std::string& what, const std::string& path) {
  if (path.empty()) return;
  struct stat status {};
  if (::lstat(path.c_str(), &status) == 0 && S_ISLNK(status.st_mode)) {
    throw UsageError(
        named(what, path) +
        " is a symbolic link: the folders a set makes are written only in place, never through a "
        "link; remove it, nothing written");
  }
  output_folder(what, path);
}

void FilePlan::existing_output_folder(const std::string& what, const std::string& path) {
  if (path.empty()) return;
  require_writable_folder(what, path, fs::path(path));
}

}  // namespace calligraphy::cli
