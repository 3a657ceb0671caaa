#pragma once
// Checks a shared library before this process loads it. dlopen of a damaged file can kill the process
// (a truncated ELF file is mapped past its end, and touching those pages raises SIGBUS), and opening a
// FIFO blocks: a library named by the user (an environment variable, an option) is checked first.
#include <string>

namespace calligraphy::devices {

/// Empty when `path` looks loadable: a regular file, not empty, a 64-bit ELF shared object of this machine
/// whose program headers and loadable segments lie inside the file. Otherwise the reason, for people
/// ("a directory", "empty", "truncated: segment 2 ends at byte 81920 of a 4096-byte file", ...). Reads
/// at most the file's headers; never blocks on a special file.
[[nodiscard]] std::string shared_library_problem(const std::string& path);

/// Loads `path` with dlopen in a child process and reports how that went: empty when it loaded and has
/// `required_symbol`, otherwise the reason ("killed by SIGBUS while loading", "did not load within 5 s",
/// the loader's message, "lacks <symbol>"). The caller's process is never at risk. `timeout_s` bounds the
/// wait; the child is killed after it.
[[nodiscard]] std::string probe_shared_library(const std::string& path, const char* required_symbol,
                                               double timeout_s = 5.0);

}  // namespace calligraphy::devices
