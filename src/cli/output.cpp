#include "cli/output.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy::cli {

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
    write_file_atomically(path, text);
  }
}

std::string read_input_file(const std::string& path, const std::string& what) {
  std::optional<std::string> text = read_file_for_update(path);
  if (!text) throw DataError(path + ": not a regular file that exists (expected " + what + ")");
  return std::move(*text);
}

int finish_standard_output(int status, const std::string& command) {
  errno = 0;
  std::cout.flush();  // synchronised with stdio: this flushes stdout, and may be where a failure shows
  const bool flushed = std::fflush(stdout) == 0;
  const int error = errno;  // a successful flush leaves errno as the first failure set it
  if (flushed && !std::ferror(stdout) && std::cout.good()) return status;
  if (status != 0) return status;  // the failure was reported already
  std::fprintf(stderr, "%s: error: standard output: cannot write%s%s\n", command.c_str(), error ? ": " : "",
               error ? std::strerror(error) : "");
  return 1;
}

}  // namespace calligraphy::cli
