#pragma once
// Where the command line's outputs go: a file, written whole or not at all (write_file_atomically), or
// standard output for the path "-"; every write is checked.
#include <string>
#include <string_view>

namespace calligraphy::cli {

/// Writes `text` to standard output and flushes it. Throws DataError ("standard output: ...") when the
/// write or the flush fails (a full disk, a closed pipe).
void write_standard_output(std::string_view text);

/// Writes `text` to the file `path` (atomically, see calligraphy/core/atomic_file.hpp) or, when `path` is
/// "-", to standard output. Throws DataError naming the path when it cannot.
void write_output(const std::string& path, std::string_view text);

/// The text of an input file (a regular file of at most 64 MiB). Throws DataError naming the path and
/// `what` it should hold when it does not exist, is not a regular file, is too large or cannot be read.
std::string read_input_file(const std::string& path, const std::string& what);

/// Flushes standard output and checks that everything written to it arrived; prints a one-line error
/// and returns 1 (or `status` when that is already an error) when not. What main() returns.
int finish_standard_output(int status, const std::string& command);

}  // namespace calligraphy::cli
