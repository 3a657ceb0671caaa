#include "calligraphy/core/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <utility>
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

  [[nodiscard]] const fs::path& path() const noexcept { return path_; }

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

// The journal of a set being replaced, in the folder of its first file: one line per file, "target\tkept\t
// temporary" (kept: the earlier file's second name, empty for a new file). Written and synced before the
// first rename and removed after the last, so that a writer killed between two renames leaves a record of
// what was under way; the next writer of a file in that folder, under the same folder lock, completes the
// set from the temporaries, which were whole and synced before the journal was written.
constexpr const char* kJournalPrefix = ".calligraphy-set-";
constexpr const char* kJournalSuffix = ".journal";

std::string unique_suffix() {
  static std::atomic<unsigned> counter{0};
  std::string suffix = std::to_string(::getpid());
  suffix.append("-").append(std::to_string(counter.fetch_add(1)));
  return suffix;
}

void write_whole(const fs::path& path, std::string_view content) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) fail(path, "cannot write the journal of a set of files", errno);
  int error = write_all(fd, content);
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  const int close_error = close_checked(fd);
  if (error == 0) error = close_error;
  if (error != 0) {
    ::unlink(path.c_str());
    fail(path, "cannot write the journal of a set of files", error);
  }
}

// Replaces a set of files with their temporaries so that a failure part way restores the earlier set: each
// earlier file first gets a second name (a hard link beside it), which a failed rename puts back.
class SetReplacement {
 public:
  SetReplacement(const std::vector<fs::path>& targets, const std::vector<bool>& existed)
      : targets_(targets), existed_(existed), kept_(targets.size()), temporaries_(targets.size()) {
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (!existed[i]) continue;
      const fs::path folder = targets[i].parent_path().empty() ? fs::path(".") : targets[i].parent_path();
      std::string name(1, '.');  // built by appends: GCC 12 warns wrongly on a + chain
      name.append(targets[i].filename().string()).append(".kept-").append(unique_suffix());
      kept_[i] = folder / name;
      // A file system without hard links (FAT) keeps no second name: that file alone cannot be put back.
      if (::link(targets[i].c_str(), kept_[i].c_str()) != 0) kept_[i].clear();
    }
  }
  SetReplacement(const SetReplacement&) = delete;
  SetReplacement& operator=(const SetReplacement&) = delete;
  ~SetReplacement() {
    remove_kept();
    if (!journal_.empty()) ::unlink(journal_.c_str());
  }

  void add_temporary(std::size_t i, const fs::path& temporary) { temporaries_[i] = temporary; }

  void write_journal() {
    if (targets_.empty()) return;
    std::string text;
    for (std::size_t i = 0; i < targets_.size(); ++i) {
      text.append(fs::absolute(targets_[i]).string()).append("\t");
      text.append(kept_[i].empty() ? std::string() : fs::absolute(kept_[i]).string()).append("\t");
      text.append(fs::absolute(temporaries_[i]).string()).append("\n");
    }
    const fs::path folder = targets_[0].parent_path().empty() ? fs::path(".") : targets_[0].parent_path();
    std::string name(kJournalPrefix);
    name.append(unique_suffix()).append(kJournalSuffix);
    const fs::path journal = folder / name;
    write_whole(journal, text);
    journal_ = journal;
    sync_folder(journal, journal);
  }

  // Targets [0, renamed) were replaced: each gets its earlier file back (a new one is removed).
  void roll_back(std::size_t renamed) noexcept {
    for (std::size_t i = 0; i < renamed; ++i) {
      if (!existed_[i]) {
        ::unlink(targets_[i].c_str());
      } else if (kept_[i].empty()) {
        continue;  // no second name could be made: the new file stays
      } else if (::rename(kept_[i].c_str(), targets_[i].c_str()) == 0) {
        kept_[i].clear();
      }
    }
  }

  void commit() noexcept {
    remove_kept();
    if (!journal_.empty()) ::unlink(journal_.c_str());
    journal_.clear();
  }

 private:
  void remove_kept() noexcept {
    for (fs::path& kept : kept_) {
      if (!kept.empty()) ::unlink(kept.c_str());
      kept.clear();
    }
  }

  std::vector<fs::path> targets_;
  std::vector<bool> existed_;
  std::vector<fs::path> kept_;
  std::vector<fs::path> temporaries_;
  fs::path journal_;
};

// The process id in a temporary's or a second name's file name (".NAME.tmp-PID-N", ".NAME.kept-PID-N"), or 0.
pid_t writer_of(const std::string& name) {
  for (const char* mark : {".tmp-", ".kept-"}) {
    const std::size_t at = name.rfind(mark);
    if (name.empty() || name[0] != '.' || at == std::string::npos) continue;
    long pid = 0;
    std::size_t i = at + std::char_traits<char>::length(mark);
    for (; i < name.size() && name[i] >= '0' && name[i] <= '9' && pid < (1L << 30); ++i)
      pid = pid * 10 + (name[i] - '0');
    if (i < name.size() && name[i] == '-' && pid > 0) return static_cast<pid_t>(pid);
  }
  return 0;
}

// Removes the temporaries and second names that a killed writer left (its process is gone): they are not
// part of any set, and would otherwise stay beside the files for ever.
void remove_dead_writers_files(const fs::path& folder) {
  std::error_code error;
  std::vector<fs::path> dead;
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
    const pid_t pid = writer_of(entry->path().filename().string());
    if (pid == 0 || pid == ::getpid()) continue;
    if (::kill(pid, 0) != 0 && errno == ESRCH) dead.push_back(entry->path());
  }
  for (const fs::path& path : dead) ::unlink(path.c_str());
}

// Completes every set a killed writer left half replaced in the folders of `targets` (held locked): each
// temporary the journal names that is still there is renamed over its target, then the earlier files'
// second names and the journal are removed. The lock says no live writer is between its renames.
void complete_interrupted_sets(const std::vector<fs::path>& targets) {
  std::set<fs::path> folders;
  for (const fs::path& target : targets)
    folders.insert(target.parent_path().empty() ? fs::path(".") : target.parent_path());
  for (const fs::path& folder : folders) {
    std::error_code error;
    for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
      const std::string name = entry->path().filename().string();
      if (!name.starts_with(kJournalPrefix) || !name.ends_with(kJournalSuffix)) continue;
      const std::optional<std::string> text = read_file_for_update(entry->path(), std::uintmax_t{1} << 20);
      if (!text) continue;
      std::size_t start = 0;
      while (start < text->size()) {
        std::size_t end_of_line = text->find('\n', start);
        if (end_of_line == std::string::npos) end_of_line = text->size();
        const std::string line = text->substr(start, end_of_line - start);
        start = end_of_line + 1;
        const std::size_t first_tab = line.find('\t');
        const std::size_t second_tab =
            first_tab == std::string::npos ? first_tab : line.find('\t', first_tab + 1);
        if (second_tab == std::string::npos) continue;
        const std::string target = line.substr(0, first_tab);
        const std::string kept = line.substr(first_tab + 1, second_tab - first_tab - 1);
        const std::string temporary = line.substr(second_tab + 1);
        if (::access(temporary.c_str(), F_OK) == 0) ::rename(temporary.c_str(), target.c_str());
        if (!kept.empty()) ::unlink(kept.c_str());
      }
      ::unlink(entry->path().c_str());
      sync_folder(entry->path(), entry->path());
    }
    remove_dead_writers_files(folder);
  }
}

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

struct AtomicFileSet::Impl {
  std::mutex mutex;
  std::vector<std::unique_ptr<TemporaryFile>> temporaries;
  std::vector<fs::path> targets;
  std::vector<bool> existed;
  std::vector<std::pair<fs::path, std::string>> in_place;  // devices and FIFOs, written last as they are
  bool committed = false;
};

AtomicFileSet::AtomicFileSet() : impl_(std::make_unique<Impl>()) {}
AtomicFileSet::~AtomicFileSet() = default;  // uncommitted temporaries are removed by their destructors

void AtomicFileSet::add(const fs::path& path, std::string_view content) {
  if (path.empty()) throw DataError("cannot write a file with an empty name");
  const fs::path target = written_path(path);
  struct stat status {};
  bool exists = false;
  if (::stat(target.c_str(), &status) == 0) {
    if (S_ISDIR(status.st_mode)) fail(path, "cannot write", EISDIR);
    if (!S_ISREG(status.st_mode)) {  // a device or FIFO: nothing to replace, written last as it is
      const std::lock_guard lock(impl_->mutex);
      impl_->in_place.emplace_back(path, std::string(content));
      return;
    }
    if (::access(target.c_str(), W_OK) != 0) fail(path, "cannot write", errno);
    exists = true;
  } else if (errno != ENOENT) {
    fail(path, "cannot write", errno);
  }
  // Written whole (synced, closed) outside the lock: files of one set may be made on several threads.
  auto temporary = std::make_unique<TemporaryFile>(target, path, status.st_mode & 07777, exists);
  temporary->write(content);
  const std::lock_guard lock(impl_->mutex);
  if (impl_->committed) throw StateError("AtomicFileSet::add after commit");
  impl_->temporaries.push_back(std::move(temporary));
  impl_->targets.push_back(target);
  impl_->existed.push_back(exists);
}

void AtomicFileSet::commit() {
  const std::lock_guard lock(impl_->mutex);
  if (impl_->committed) throw StateError("AtomicFileSet::commit twice");
  impl_->committed = true;
  const std::vector<fs::path>& targets = impl_->targets;
  // Renames need no data blocks: once every temporary is whole, the set is replaced in one short run, under
  // an exclusive lock of each folder, so that two writers of one set never interleave their renames. A set
  // that a killed writer left half replaced is completed first (its journal, above).
  {
    const FolderLocks locks(targets);
    complete_interrupted_sets(targets);
    SetReplacement replacement(targets, impl_->existed);
    for (std::size_t i = 0; i < targets.size(); ++i)
      replacement.add_temporary(i, impl_->temporaries[i]->path());
    replacement.write_journal();
    for (std::size_t i = 0; i < targets.size(); ++i) {
      try {
        impl_->temporaries[i]->rename_to(targets[i]);
      } catch (const DataError&) {
        replacement.roll_back(i);  // the earlier set again, then the error naming the file at fault
        throw;
      }
    }
    replacement.commit();
  }
  for (const fs::path& target : targets) sync_folder(target, target);
  for (const auto& [path, content] : impl_->in_place) write_in_place(path, content);
}

void write_files_atomically(std::span<const FileContent> files) {
  AtomicFileSet set;
  for (const FileContent& file : files) set.add(file.path, file.content);
  set.commit();
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
