#include "core/whole_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <memory>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

DataError no_such_file(const std::filesystem::path& path, const std::string& expected) {
  std::string notes = expected.empty() ? "" : "expected " + expected;
  // `-` means standard output for an output; an input is never standard input (it must be a regular file).
  if (path == "-") {
    notes += (notes.empty() ? "" : "; ");
    notes += "standard input is not read: every input is a regular file; save it to one first";
  }
  return DataError(path.string() + ": no such file" + (notes.empty() ? "" : " (" + notes + ")"));
}

DataError missing_input(const std::filesystem::path& path, const std::error_code& error,
                        const std::string& expected) {
  if (error.value() != ELOOP) return no_such_file(path, expected);
  return DataError(path.string() + ": cannot resolve the symbolic link: " + std::strerror(ELOOP) +
                   (expected.empty() ? "" : " (expected " + expected + ")"));
}

std::uintmax_t regular_file_size(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw missing_input(path, error);
  if (!std::filesystem::is_regular_file(status)) throw DataError(name + ": not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw DataError(name + ": cannot read its size (" + error.message() + ")");
  if (size > max_bytes) {
    throw DataError(name + ": " + std::to_string(size) + " bytes, more than the limit of " +
                    std::to_string(max_bytes));
  }
  return size;
}

std::string read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  (void)regular_file_size(path, max_bytes);
  // O_NONBLOCK: a FIFO put in the file's place since the check above is refused below, never waited on.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw DataError(name + ": cannot be opened (" + std::strerror(errno) + ")");
  const std::unique_ptr<const int, void (*)(const int*)> closer(&fd, [](const int* f) { ::close(*f); });
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) throw DataError(name + ": not a regular file");
  // Read to its end, not to the size stat(2) gave: a /proc file says 0 bytes and has content, and a file
  // that grows or shrinks meanwhile is read as it then is; never more than max_bytes.
  std::string text;
  std::array<char, 65536> buffer{};
  for (;;) {
    const ssize_t got = ::read(fd, buffer.data(), buffer.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw DataError(name + ": could not be read whole (" + std::strerror(errno) + ")");
    if (got == 0) return text;
    if (text.size() + static_cast<std::size_t>(got) > max_bytes) {
      throw DataError(name + ": more bytes than the limit of " + std::to_string(max_bytes) +
                      " (it grew while it was read)");
    }
    text.append(buffer.data(), static_cast<std::size_t>(got));
  }
}

const char* file_kind(mode_t mode) noexcept {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace calligraphy
