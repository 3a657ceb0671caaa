#include "calligraphy/core/atomic_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <memory>
#include <set>
#include <system_error>
#include <vector>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& path, const std::string& what, int error) {
  throw DataError(path.string() + ": " + what + ": " + std::generic_category().message(error));
}

// Writes all of `content`, resuming after EINTR and short writes. Returns 0 or the errno of the failure.
int write_all(int fd, std::string_view content) {
  while (!content.empty()) {
    const ssize_t written = ::write(fd, content.data(), content.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (written == 0) return EIO;  // no progress and no error: give up rather than spin
    content.remove_prefix(static_cast<std::size_t>(written));
  }
  return 0;
}

// close(2) once; EINTR is not retried (Linux releases the descriptor anyway).
int close_checked(int& fd) {
  const int result = ::close(fd);
  fd = -1;
  return result == 0 || errno == EINTR ? 0 : errno;
}

// A device, FIFO or terminal: written as it is; there is no file to replace.
void write_in_place(const fs::path& path, std::string_view content) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) fail(path, "cannot open for writing", errno);
  const int write_error = write_all(fd, content);
  const int close_error = close_checked(fd);
  if (write_error != 0) fail(path, "cannot write", write_error);
  if (close_error != 0) fail(path, "cannot write (on close)", close_error);
}

// The temporary file beside the target, removed on destruction unless committed.
class TemporaryFile {
 public:
  TemporaryFile(const fs::path& target, const fs::path& reported, mode_t mode, bool set_mode)
      : reported_(reported) {
    static std::atomic<unsigned> counter{0};
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    for (int attempt = 0; attempt < 100; ++attempt) {
      std::string name(1, '.');  // hidden, beside the target; built by appends (GCC 12 warns on a + chain)
      name.append(target.filename().string()).append(".tmp-").append(std::to_string(::getpid()));
      name.append("-").append(std::to_string(counter.fetch_add(1)));
      path_ = folder / name;
      fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, set_mode ? 0600 : 0666);
      if (fd_ >= 0 || errno != EEXIST) break;
    }
    if (fd_ < 0) fail(reported_, "cannot create a temporary file in " + folder.string(), errno);
    if (set_mode && ::fchmod(fd_, mode) != 0) fail_and_remove("cannot set the permissions", errno);
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() { remove(); }

  void write(std::string_view content) {
    if (const int error = write_all(fd_, content)) fail_and_remove("cannot write", error);
    if (::fsync(fd_) != 0) fail_and_remove("cannot write (fsync)", errno);
    if (const int error = close_checked(fd_)) fail_and_remove("cannot write (on close)", error);
  }

  void rename_to(const fs::path& target) {
    if (::rename(path_.c_str(), target.c_str()) != 0) fail_and_remove("cannot replace the file", errno);
    committed_ = true;
  }

 private:
  void remove() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!committed_) ::unlink(path_.c_str());
    committed_ = true;
  }
  [[noreturn]] void fail_and_remove(const std::string& what, int error) {
    remove();
    fail(reported_, what, error);
  }

  fs::path reported_;
  fs::path path_;
  int fd_ = -1;
  bool committed_ = false;
};

// The folder holds the new directory entry only once it is synced; a folder that cannot be opened or
// synced (some file systems refuse fsync on directories: EINVAL) leaves the file written but the rename
// possibly not yet durable, which is reported unless the file system does not support it.
void sync_folder(const fs::path& target, const fs::path& reported) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // written and renamed; only the durability of the rename is not confirmed
  const int result = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (result != 0 && error != EINVAL && error != EROFS) {
    fail(reported, "written, but its folder could not be synced", error);
  }
}

// flock(2) on the folders of a set's targets, taken in sorted order (no two writers deadlock) and released
// on destruction. A folder that cannot be opened or locked is left unlocked: the renames go on as before.
class FolderLocks {
 public:
  explicit FolderLocks(const std::vector<fs::path>& targets) {
    std::set<fs::path> folders;
    for (const fs::path& target : targets) {
      folders.insert(target.parent_path().empty() ? fs::path(".") : target.parent_path());
    }
    for (const fs::path& folder : folders) {
      const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;
      while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
      }
      fds_.push_back(fd);
    }
  }
  FolderLocks(const FolderLocks&) = delete;
  FolderLocks& operator=(const FolderLocks&) = delete;
  ~FolderLocks() {
    for (const int fd : fds_) ::close(fd);
  }

 private:
  std::vector<int> fds_;
};

}  // namespace

fs::path written_path(const fs::path& path) {
  fs::path current = path;
  for (int links = 0; links <= 40; ++links) {
    struct stat status {};
    if (::lstat(current.c_str(), &status) != 0 || !S_ISLNK(status.st_mode)) return current;
    std::error_code error;
    const fs::path target = fs::read_symlink(current, error);
    if (error) fail(path, "cannot read the symbolic link", error.value());
    current = target.is_absolute() ? target : current.parent_path() / target;
  }
  fail(path, "cannot resolve the symbolic link", ELOOP);
}

void write_file_atomically(const fs::path& path, std::string_view content) {
  if (path.empty()) throw DataError("cannot write a file with an empty name");
  // A symbolic link keeps pointing where it did: the file it names is replaced, or created when the link
  // dangles.
  const fs::path target = written_path(path);
  struct stat status {};
  bool exists = false;
  if (::stat(target.c_str(), &status) == 0) {
    if (!S_ISREG(status.st_mode)) return write_in_place(path, content);
    // A read-only file stays as it is, as it would were it overwritten in place (the rename alone needs
    // only the folder's permission).
    if (::access(target.c_str(), W_OK) != 0) fail(path, "cannot write", errno);
    exists = true;
  } else if (errno != ENOENT) {
    fail(path, "cannot write", errno);
  }
  TemporaryFile temporary(target, path, status.st_mode & 07777, exists);
  temporary.write(content);
  temporary.rename_to(target);
  sync_folder(target, path);
}

void write_files_atomically(std::span<const FileContent> files) {
  // Every temporary is written, synced and closed before any target is replaced: a failure while writing
  // (a full disk) removes them all and leaves every earlier file as it was.
  std::vector<std::unique_ptr<TemporaryFile>> temporaries;
  std::vector<fs::path> targets;
  std::vector<const FileContent*> in_place;
  for (const FileContent& file : files) {
    if (file.path.empty()) throw DataError("cannot write a file with an empty name");
    const fs::path target = written_path(file.path);
    struct stat status {};
    bool exists = false;
    if (::stat(target.c_str(), &status) == 0) {
      if (S_ISDIR(status.st_mode)) fail(file.path, "cannot write", EISDIR);
      if (!S_ISREG(status.st_mode)) {  // a device or FIFO: nothing to replace, written last as it is
        in_place.push_back(&file);
        continue;
      }
      if (::access(target.c_str(), W_OK) != 0) fail(file.path, "cannot write", errno);
      exists = true;
    } else if (errno != ENOENT) {
      fail(file.path, "cannot write", errno);
    }
    temporaries.push_back(std::make_unique<TemporaryFile>(target, file.path, status.st_mode & 07777, exists));
    temporaries.back()->write(file.content);
    targets.push_back(target);
  }
  // Renames need no data blocks: once every temporary is whole, the set is replaced in one short run, under
  // an exclusive lock of each folder, so that two writers of one set never interleave their renames.
  const FolderLocks locks(targets);
  for (std::size_t i = 0; i < temporaries.size(); ++i) temporaries[i]->rename_to(targets[i]);
  for (const fs::path& target : targets) sync_folder(target, target);
  for (const FileContent* file : in_place) write_in_place(file->path, file->content);
}

void write_file_atomically(const fs::path& path, std::span<const std::uint8_t> content) {
  write_file_atomically(path,
                        std::string_view(reinterpret_cast<const char*>(content.data()), content.size()));
}

std::optional<std::string> read_file_for_update(const fs::path& path, std::uintmax_t max_bytes) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    if (errno == ENOENT) return std::nullopt;
    fail(path, "cannot read", errno);
  }
  if (!S_ISREG(status.st_mode)) return std::nullopt;
  const auto size = static_cast<std::uintmax_t>(status.st_size);
  if (size > max_bytes) {
    throw DataError(path.string() + ": " + std::to_string(size) + " bytes, more than the limit of " +
                    std::to_string(max_bytes) + " for a file that is updated in place");
  }
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, "cannot open for reading", errno);
  std::string text;
  char buffer[65536];
  while (true) {
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const int error = errno;
      close_checked(fd);
      fail(path, "cannot read", error);
    }
    if (got == 0) break;
    text.append(buffer, static_cast<std::size_t>(got));
    if (text.size() > max_bytes) {  // the file grew while it was read
      close_checked(fd);
      throw DataError(path.string() + ": more than " + std::to_string(max_bytes) + " bytes");
    }
  }
  close_checked(fd);
  return text;
}

}  // namespace calligraphy
