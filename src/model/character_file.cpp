#include "model/character_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "core/whole_file.hpp"

namespace calligraphy::detail {
namespace {

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string read_character_file(const std::filesystem::path& path, char32_t code_point,
                                std::size_t max_bytes) {
  const std::string name = path.string();
  const auto refuse = [&](const std::string& why) -> DataError {
    return DataError(name + ": character " + describe_character(code_point) + ": " + why);
  };
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (fd.get() < 0) {
    const int error = errno;
    if (error == ENOENT || error == ENOTDIR) {
      throw CharacterNotFound("character " + describe_character(code_point) + " not found: no file " + name);
    }
    if (error == EMFILE || error == ENFILE || error == ENOMEM) {
      // The machine's limit (the open files this process or the system may have, or memory), not the file's
      // fault: an Error, which a reader that skips a bad character file does not take for one.
      throw Error(name + ": cannot open (" + std::strerror(error) +
                  "): the files this process may open, or its memory, are used up; the file was not read");
    }
    throw refuse(std::string("cannot open (") + std::strerror(error) + ")");
  }
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0) throw refuse(std::string("cannot stat (") + std::strerror(errno) + ")");
  if (!S_ISREG(info.st_mode)) {
    throw refuse(std::string(file_kind(info.st_mode)) + ", not a regular file: refused unread");
  }
  if (info.st_size < 0 || static_cast<std::uintmax_t>(info.st_size) > max_bytes) {
    throw refuse(std::to_string(info.st_size) + " bytes, more than the " + std::to_string(max_bytes) +
                 " a character file may have");
  }
  // Read at most max_bytes + 1, in case the file grew since fstat.
  std::string text(static_cast<std::size_t>(info.st_size), '\0');
  std::size_t filled = 0;
  for (;;) {
    if (filled == text.size()) {
      if (text.size() > max_bytes) break;
      text.resize(std::min(max_bytes + 1, text.size() + 4096));
    }
    const ssize_t got = ::read(fd.get(), text.data() + filled, text.size() - filled);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw refuse(std::string("read failed (") + std::strerror(errno) + ")");
    }
    if (got == 0) break;
    filled += static_cast<std::size_t>(got);
  }
  if (filled > max_bytes) {
    throw refuse("more than the " + std::to_string(max_bytes) + " bytes a character file may have");
  }
  text.resize(filled);
  return text;
}

}  // namespace calligraphy::detail
