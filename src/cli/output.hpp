#pragma once
// Where the command line's outputs go: a file, written whole or not at all (write_file_atomically), or
// standard output for the path "-"; every write is checked. The one way a command's files leave it: each
// file is checked by a FilePlan before anything runs, then written by write_output or an OutputSet, which
// refuse a file no plan checked.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"

namespace calligraphy::cli {

/// Writes `text` to standard output and flushes it. Throws DataError ("standard output: ...") when the
/// write or the flush fails (a full disk, a closed pipe).
void write_standard_output(std::string_view text);

/// Writes `text` to the file `path` (atomically, see calligraphy/core/atomic_file.hpp) or, when `path` is
/// "-", to standard output. Throws DataError naming the path when it cannot, StateError (a program error)
/// when no FilePlan of this process checked `path` as an output first.
void write_output(const std::string& path, std::string_view text);
/// The same for binary content (a corpus store).
void write_output(const std::string& path, std::span<const std::uint8_t> bytes);

/// Files of one command replaced together (AtomicFileSet: the earlier set or the whole new one), each
/// checked first by a FilePlan as write_output requires. `add` may be called from several threads. Throws
/// as AtomicFileSet does, and StateError for a file no plan checked.
class OutputSet {
 public:
  void add(const std::filesystem::path& path, std::string_view content);
  void commit();

 private:
  AtomicFileSet set_;
};

/// The text of an input file (a regular file of at most 64 MiB). Throws DataError naming the path and
/// `what` it should hold when it does not exist, is not a regular file, is too large or cannot be read.
std::string read_input_file(const std::string& path, const std::string& what);

/// Prints "COMMAND: KIND: MESSAGE" as one line on standard error ("calligraphy trial", "error", ...): control
/// characters in any part escaped and the message's length bounded (printable_one_line), whatever it quotes
/// (docs/cli.md, "Errors").
void print_error_line(std::string_view command, std::string_view kind, std::string_view message);

/// `text` (a path the user gave, a folder made of it) as printable text, never cut: for the lines a command
/// prints about what it did, so that a line break or an escape sequence in a name keeps the line one line and
/// cannot act on the terminal (printable_one_line).
std::string printable_name(std::string_view text);

/// Flushes standard output and checks that everything written to it arrived; prints a one-line error
/// and returns 1 (or `status` when that is already an error) when not. What main() returns.
int finish_standard_output(int status, const std::string& command);

/// The files one command reads and writes, checked before its first trial and its first write
/// (docs/cli.md, "Outputs"). Inputs are registered first, then each output is checked as it is added:
///  - a path is resolved through symbolic links (a dangling link to the file it names, which is where
///    write_file_atomically writes) and identified by (device, inode) when the file exists, by the resolved
///    path when it does not;
///  - an output may not be the same file as another output or any input (UsageError, exit 2, naming both
///    options and paths); a file under a folder of saved records counts as an input;
///  - an output file's folder must exist and be writable, an existing output file writable, and an
///    output that names a folder is refused (DataError, exit 1, naming the option and path).
/// "" and "-" (standard output) are not files. An existing device or FIFO (/dev/null) is written in place,
/// never replaced, and may be given more than once.
class FilePlan {
 public:
  /// A file the command reads, named `what` in messages ("--teacher", "TRACE").
  void input(const std::string& what, const std::string& path);
  /// A folder the command reads (--data, a session folder): every regular file under it is an input.
  void input_folder(const std::string& what, const std::string& path);
  /// A file the command writes (write_output). Throws as the class comment says.
  void output(const std::string& what, const std::string& path);
  /// A file of a set the command writes (OutputSet): checked as `output`, and in addition refused when it is
  /// a symbolic link (UsageError, exit 2, naming the option and path), since a set is written only in its
  /// own folders, never through a link (AtomicFileSet).
  void set_output(const std::string& what, const std::string& path);
  /// A folder the command creates files or folders in: it must be a writable folder, or not exist yet
  /// with a writable folder as its nearest existing ancestor. Throws DataError naming `what` and the path.
  /// Outputs given after it may lie in it, or in subfolders of it, before they exist: the command makes them.
  void output_folder(const std::string& what, const std::string& path);
  /// A folder a set makes for its files (report's NAME_files/ and its subjects' folders): as output_folder,
  /// and a symbolic link in its place is refused (UsageError naming `what` and the path), as a set's file is,
  /// so a link planted there cannot carry the set's files out of it.
  void set_output_folder(const std::string& what, const std::string& path);
  /// An existing folder the command writes new files into (e.g. screenshots): it must exist and be
  /// writable. Throws DataError naming `what` and the path.
  void existing_output_folder(const std::string& what, const std::string& path);

  /// The identity of a file: exists, (device, inode), resolved path.
  struct Identity {
    bool exists = false;
    bool regular = false;
    bool folder = false;
    unsigned long long device = 0;
    unsigned long long inode = 0;
    std::string path;  ///< the resolved path (canonical when it exists)
  };

 private:
  struct Entry {
    std::string what;
    std::string given;  ///< the path as given
    Identity identity;
  };
  void add_input(const std::string& what, const std::string& given, const Identity& identity);
  std::vector<Entry> inputs_;
  std::vector<Entry> outputs_;
  std::vector<std::filesystem::path> output_folders_;  // folders the command makes files and folders in
};

/// Every file of every session folder under `root` (find_session_folders: the saved trial records,
/// session.json, the log, the kept teachers) as an input of `plan`, named `what` ("DIR", "--out"). Other
/// files under `root` (an earlier report page) are not inputs. A `root` that is not a folder adds nothing:
/// the command's reader names it.
void add_saved_sessions(FilePlan& plan, const std::string& what, const std::string& root);

/// The identity of `path` (see FilePlan): symbolic links followed, a dangling one to the path it names.
/// Throws DataError naming `what` and the path when a link loops or a component cannot be examined.
FilePlan::Identity identify_file(const std::string& what, const std::string& path);

}  // namespace calligraphy::cli
