#include "calligraphy/core/atomic_file.hpp"

#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/stop_signals.hpp"

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
// How long a FIFO may wait for a process to read it: an output is never a hang, and a reader started beside
// the writer (`cat FIFO & calligraphy ... --csv FIFO`) has this long to open it.
constexpr int kFifoReaderWaitMs = 10000;

// A FIFO opened for writing without waiting (O_NONBLOCK: ENXIO while no process has it open to read), tried
// again every 20 ms until a reader comes or kFifoReaderWaitMs pass; then writes block as they do on any pipe.
int open_fifo_for_writing(const fs::path& path) {
  for (int waited_ms = 0;; waited_ms += 20) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd >= 0) {
      const int flags = ::fcntl(fd, F_GETFL);
      if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        const int error = errno;
        ::close(fd);
        fail(path, "cannot open for writing", error);
      }
      return fd;
    }
    if (errno != ENXIO) fail(path, "cannot open for writing", errno);
    if (waited_ms >= kFifoReaderWaitMs) {
      throw DataError(path.string() + ": cannot write: a FIFO that no process opened for reading within " +
                      std::to_string(kFifoReaderWaitMs / 1000) + " s");
    }
    ::usleep(20000);
  }
}

void write_in_place(const fs::path& path, std::string_view content) {
  struct stat status {};
  const bool fifo = ::stat(path.c_str(), &status) == 0 && S_ISFIFO(status.st_mode);
  int fd = fifo ? open_fifo_for_writing(path) : ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) fail(path, "cannot open for writing", errno);
  const int write_error = write_all(fd, content);
  const int close_error = close_checked(fd);
  if (write_error != 0) fail(path, "cannot write", write_error);
  if (close_error != 0) fail(path, "cannot write (on close)", close_error);
}

// The temporaries this process has open, for the stop-signal handler (guard_output_files): fixed slots of
// fixed size, claimed and released with atomics, so that the handler reads them without a lock or an
// allocation. A path too long for a slot, or a 65th temporary at once, is not removed by a signal (it is on
// every other path, and a later writer in that folder removes it, below: remove_dead_writers_files).
struct TemporarySlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a live temporary's path
  char path[PATH_MAX];
};
TemporarySlot temporary_slots[64];
std::atomic<int> committing_sets{0};  // sets between their first and last rename: a signal waits for them
std::atomic<int> deferred_signal{0};  // the stop signal that came during a set's renames
std::atomic<bool> signals_guarded{false};

int claim_slot(std::span<TemporarySlot> slots, const fs::path& path) noexcept {
  const std::string& text = path.native();
  if (text.size() >= PATH_MAX) return -1;
  for (int i = 0; i < static_cast<int>(slots.size()); ++i) {
    int free_slot = 0;
    if (!slots[static_cast<std::size_t>(i)].state.compare_exchange_strong(free_slot, 1)) continue;
    std::memcpy(slots[static_cast<std::size_t>(i)].path, text.c_str(), text.size() + 1);
    slots[static_cast<std::size_t>(i)].state.store(2);
    return i;
  }
  return -1;
}

// Holds the stop signals back while it lives (this thread): a temporary created and not yet registered
// would be left behind by a signal that came between the two; one held back is handled when it ends, with
// the temporary registered.
class StopSignalsHeld {
 public:
  StopSignalsHeld() noexcept {
    sigset_t held;
    sigemptyset(&held);
    for (const int signal : stop_signal_numbers()) sigaddset(&held, signal);
    pthread_sigmask(SIG_BLOCK, &held, &before_);
  }
  StopSignalsHeld(const StopSignalsHeld&) = delete;
  StopSignalsHeld& operator=(const StopSignalsHeld&) = delete;
  ~StopSignalsHeld() { pthread_sigmask(SIG_SETMASK, &before_, nullptr); }

 private:
  sigset_t before_{};
};

int register_temporary(const fs::path& path) noexcept { return claim_slot(temporary_slots, path); }

void release_temporary(int slot) noexcept {
  if (slot >= 0) temporary_slots[slot].state.store(0);
}

// The folders commands made for their outputs (register_made_folder), in slots as the temporaries'.
TemporarySlot made_folder_slots[256];

// Async-signal-safe: unlink(2) of every live temporary, then rmdir(2) of every made folder still empty. A
// folder is emptied only by its subfolders' removal, so each pass removes one level more: a made folder is at
// most a few levels below another (a report's NAME_files/SUBJECT/), and eight passes outlast any nesting
// here.
void remove_live_temporaries() noexcept {
  for (TemporarySlot& slot : temporary_slots) {
    if (slot.state.load() == 2) ::unlink(slot.path);
  }
  for (int pass = 0; pass < 8; ++pass) {
    for (TemporarySlot& slot : made_folder_slots) {
      if (slot.state.load() == 2) ::rmdir(slot.path);
    }
  }
}

// Ends the process by `signal` as its default action would, once the temporaries are gone.
void die_by(int signal) noexcept {
  remove_live_temporaries();
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  sigaction(signal, &action, nullptr);
  sigset_t unblock;
  sigemptyset(&unblock);
  sigaddset(&unblock, signal);
  pthread_sigmask(SIG_UNBLOCK, &unblock, nullptr);
  ::raise(signal);
}

extern "C" void remove_temporaries_then_die(int signal) {
  if (committing_sets.load() > 0) {  // a set is between its renames: it finishes them, then dies
    int none = 0;
    deferred_signal.compare_exchange_strong(none, signal);
    return;
  }
  die_by(signal);
}

// Marks a set's renames: a stop signal meanwhile waits until the last one is done (or undone).
class RenamesUnderWay {
 public:
  RenamesUnderWay() noexcept { committing_sets.fetch_add(1); }
  RenamesUnderWay(const RenamesUnderWay&) = delete;
  RenamesUnderWay& operator=(const RenamesUnderWay&) = delete;
  ~RenamesUnderWay() {
    if (committing_sets.fetch_sub(1) == 1) {
      const int signal = deferred_signal.exchange(0);
      if (signal != 0) die_by(signal);
    }
  }
};

// ".NAME" and `mark`: how a temporary's or a second name's file name beside `target` starts
// (".NAME.tmp-PID-N",
// ".NAME.kept-PID-N"). A file name is at most NAME_MAX (255) bytes, so a NAME that leaves no room for the
// mark and "PID-N" is cut (at the start of a UTF-8 character): a target with the longest name the file system
// takes gets a temporary it takes too. Its writer, its journal's reader and the removal of a dead writer's
// files all use this one prefix.
std::string sibling_prefix(const fs::path& target, std::string_view mark) {
  constexpr std::size_t kSuffixRoom = 2 * 20 + 1;  // "PID-N": two 64-bit numbers in decimal and the '-'
  std::string name = target.filename().string();
  const std::size_t room = NAME_MAX - 1 - mark.size() - kSuffixRoom;
  if (name.size() > room) {
    std::size_t cut = room;
    while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0U) == 0x80U) --cut;
    name.resize(cut);
  }
  std::string prefix(1, '.');  // built by appends: GCC 12 warns wrongly on a + chain
  prefix.append(name).append(mark);
  return prefix;
}

// The temporary file beside the target, removed on destruction unless committed.
class TemporaryFile {
 public:
  TemporaryFile(const fs::path& target, const fs::path& reported, mode_t mode, bool set_mode)
      : reported_(reported) {
    static std::atomic<unsigned> counter{0};
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const StopSignalsHeld held;  // from the file's creation to its registration
    for (int attempt = 0; attempt < 100; ++attempt) {
      std::string name = sibling_prefix(target, ".tmp-");  // hidden, beside the target
      name.append(std::to_string(::getpid()));
      name.append("-").append(std::to_string(counter.fetch_add(1)));
      path_ = folder / name;
      fd_ =
          ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, set_mode ? 0600 : 0666);
      if (fd_ >= 0 || errno != EEXIST) break;
    }
    if (fd_ < 0) fail(reported_, "cannot create a temporary file in " + folder.string(), errno);
    slot_ = register_temporary(path_);
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

  /// Gives the written temporary the name `target` too (link(2): never replaces an existing file); the
  /// temporary's own name is removed on destruction. Returns 0 or link's errno.
  [[nodiscard]] int link_to(const fs::path& target) noexcept {
    return ::link(path_.c_str(), target.c_str()) == 0 ? 0 : errno;
  }

  void rename_to(const fs::path& target) {
    if (::rename(path_.c_str(), target.c_str()) != 0) fail_and_remove("cannot replace the file", errno);
    committed_ = true;
    release_temporary(slot_);
    slot_ = -1;
  }

 private:
  void remove() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!committed_) ::unlink(path_.c_str());
    committed_ = true;
    release_temporary(slot_);
    slot_ = -1;
  }
  [[noreturn]] void fail_and_remove(const std::string& what, int error) {
    remove();
    fail(reported_, what, error);
  }

  fs::path reported_;
  fs::path path_;
  int fd_ = -1;
  int slot_ = -1;
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

// The folder a target is in ("." for a bare name).
fs::path folder_of(const fs::path& target) {
  return target.parent_path().empty() ? fs::path(".") : target.parent_path();
}

// A folder resolved through symbolic links (as it is, made absolute, when it cannot be).
fs::path resolved_folder(const fs::path& folder) {
  std::error_code error;
  fs::path resolved = fs::canonical(folder, error);
  return error ? fs::absolute(folder).lexically_normal() : resolved;
}

// The folders of a set, each (resolved) with the indices of its targets in the order they were added, in the
// sorted order of the folders: a set is committed folder by folder, each folder under its own journal.
struct SetFolder {
  fs::path folder;
  std::vector<std::size_t> files;
};

std::vector<SetFolder> folders_of_set(const std::vector<fs::path>& targets) {
  std::vector<SetFolder> folders;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const fs::path folder = resolved_folder(folder_of(targets[i]));
    auto found =
        std::find_if(folders.begin(), folders.end(), [&](const SetFolder& f) { return f.folder == folder; });
    if (found == folders.end()) found = folders.insert(folders.end(), SetFolder{folder, {}});
    found->files.push_back(i);
  }
  std::sort(folders.begin(), folders.end(),
            [](const SetFolder& a, const SetFolder& b) { return a.folder < b.folder; });
  return folders;
}

// flock(2) on a set's folders, taken in sorted order (no two writers deadlock) and released on destruction.
// A folder that cannot be opened or locked is left unlocked: the renames go on as before.
class FolderLocks {
 public:
  explicit FolderLocks(const std::vector<SetFolder>& folders) {
    for (const SetFolder& set_folder : folders) {
      const int fd = ::open(set_folder.folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
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

// The journal of a set's files in one folder, `.calligraphy-set-PID-N.journal` in that folder (a set whose
// targets are in several folders has one journal in each, and needs no other folder):
//
//   calligraphy-set-journal 3
//   TARGET<tab>KEPT<tab>TEMPORARY      one line per file of the set in this folder
//   checksum HHHHHHHHHHHHHHHH           FNV-1a (64 bits) of every byte before this line, in hex
//
// TARGET, KEPT (the earlier file's second name, empty for a new file) and TEMPORARY are file names in the
// journal's own folder: no "/", never "." or ".."; KEPT and TEMPORARY of the forms this writer gives them
// (".NAME.kept-...", ".NAME.tmp-..."). Every journal of a set is written whole under a temporary name, synced
// and renamed into place before the set's first rename; the set is then replaced folder by folder, and each
// folder's journal is removed once that folder's renames are done. So a writer killed part way leaves each
// folder of the set either replaced, or holding a journal of what was under way there; the next writer of a
// set in that folder, under the same folder lock, completes it from the temporaries, which were whole and
// synced before any journal was written. Because every name is a name in the journal's folder, a journal
// copied with its folder completes the copy only; a journal that is not this writer's (another tag or
// version, a checksum that differs, a name with a "/" or that is "." or "..", a file it names that is a
// symbolic link or not a regular file) is refused and left as it is.
constexpr const char* kJournalPrefix = ".calligraphy-set-";
constexpr const char* kJournalSuffix = ".journal";
constexpr std::string_view kJournalHeader = "calligraphy-set-journal 3\n";
constexpr std::string_view kJournalChecksum = "checksum ";

std::string unique_suffix() {
  static std::atomic<unsigned> counter{0};
  std::string suffix = std::to_string(::getpid());
  suffix.append("-").append(std::to_string(counter.fetch_add(1)));
  return suffix;
}

std::string journal_checksum(std::string_view text) {
  std::uint64_t hash = 14695981039346656037ULL;  // FNV-1a, 64 bits
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, hash);
  return hex;
}

// Replaces a set of files with their temporaries so that a failure part way restores the earlier set: each
// earlier file first gets a second name (a hard link beside it), which a failed rename puts back.
class SetReplacement {
 public:
  SetReplacement(const std::vector<fs::path>& targets, const std::vector<bool>& existed)
      : targets_(targets), existed_(existed), kept_(targets.size()), temporaries_(targets.size()) {
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (!existed[i]) continue;
      std::string name = sibling_prefix(targets[i], ".kept-");
      name.append(unique_suffix());
      kept_[i] = folder_of(targets[i]) / name;
      // A file system without hard links (FAT) keeps no second name: that file alone cannot be put back.
      if (::link(targets[i].c_str(), kept_[i].c_str()) != 0) kept_[i].clear();
    }
  }
  SetReplacement(const SetReplacement&) = delete;
  SetReplacement& operator=(const SetReplacement&) = delete;
  ~SetReplacement() {
    remove_kept();
    for (const fs::path& journal : journals_) {
      if (!journal.empty()) ::unlink(journal.c_str());
    }
  }

  void add_temporary(std::size_t i, const fs::path& temporary) { temporaries_[i] = temporary; }

  // One journal in each folder of the set, naming that folder's files only; all are in place before the
  // first rename. A folder that cannot take its journal throws before any target changes.
  void write_journals(const std::vector<SetFolder>& folders) {
    journals_.assign(folders.size(), fs::path());
    for (std::size_t f = 0; f < folders.size(); ++f) {
      std::string text(kJournalHeader);
      for (const std::size_t i : folders[f].files) {
        text.append(targets_[i].filename().string()).append("\t");
        text.append(kept_[i].filename().string()).append("\t");
        text.append(temporaries_[i].filename().string()).append("\n");
      }
      const std::string checksum = journal_checksum(text);  // of every byte before the checksum line
      text.append(kJournalChecksum).append(checksum).append("\n");
      std::string name(kJournalPrefix);
      name.append(unique_suffix()).append(kJournalSuffix);
      const fs::path journal = folders[f].folder / name;
      // Whole or absent: a writer killed while writing it leaves a temporary, which is no journal.
      TemporaryFile temporary(journal, journal, 0600, true);
      temporary.write(text);
      temporary.rename_to(journal);
      journals_[f] = journal;
      sync_folder(journal, journal);
    }
  }

  // The renames of folder `f` are done: they are made durable (as far as the file system allows) before its
  // journal goes, so that the folder is never left changed without a record.
  void folder_done(std::size_t f) noexcept {
    if (f >= journals_.size() || journals_[f].empty()) return;
    const int fd = ::open(journals_[f].parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
      ::fsync(fd);
      ::close(fd);
    }
    ::unlink(journals_[f].c_str());
    journals_[f].clear();
  }

  // The targets in `renamed` were replaced: each gets its earlier file back (a new one is removed).
  void roll_back(const std::vector<std::size_t>& renamed) noexcept {
    for (const std::size_t i : renamed) {
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
    for (fs::path& journal : journals_) {
      if (!journal.empty()) ::unlink(journal.c_str());
      journal.clear();
    }
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
  std::vector<fs::path> journals_;  // one per folder of the set, cleared once that folder is done
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

// Removes the temporaries of `target` that a killed writer left beside it (".NAME.tmp-PID-N", its process
// gone): a writer killed by SIGKILL cannot remove its own.
void remove_dead_writers_temporaries(const fs::path& target) {
  const std::string prefix = sibling_prefix(target, ".tmp-");
  std::error_code error;
  std::vector<fs::path> dead;
  for (fs::directory_iterator entry(folder_of(target), error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (!name.starts_with(prefix)) continue;
    const pid_t pid = writer_of(name);
    if (pid != 0 && pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) dead.push_back(entry->path());
  }
  for (const fs::path& path : dead) ::unlink(path.c_str());
}

// One file of a journal, resolved: its target, the earlier file's second name (empty: none), the temporary.
struct JournalEntry {
  fs::path target;
  fs::path kept;
  fs::path temporary;
};

[[noreturn]] void refuse_journal(const fs::path& journal, const std::string& why) {
  throw DataError(journal.string() + ": " + why +
                  ": not the journal of a set this writer left in this folder; refused and left as it is "
                  "(nothing was written; remove it once the files it names are checked)");
}

// A name of a file in the target's folder, of the form this writer gives it (".NAME" + mark + "...").
bool sibling_name(const std::string& name, const fs::path& target, const char* mark) {
  const std::string prefix = sibling_prefix(target, mark);
  return name.size() > prefix.size() && name.starts_with(prefix) && name.find('/') == std::string::npos;
}

// A regular file, not there, or neither (a link, a folder, ...): refused.
bool regular_or_absent(const fs::path& path) {
  struct stat status {};
  if (::lstat(path.c_str(), &status) != 0) return errno == ENOENT;
  return S_ISREG(status.st_mode);
}

// The files a journal in `folder` (resolved) names, every one checked as the journal's comment says before
// any is touched. Throws DataError naming the journal when anything differs.
std::vector<JournalEntry> read_journal(const fs::path& journal, const fs::path& folder) {
  struct stat status {};
  if (::lstat(journal.c_str(), &status) != 0) return {};  // completed meanwhile
  if (!S_ISREG(status.st_mode)) refuse_journal(journal, "not a regular file");
  std::optional<std::string> text;
  try {
    text = read_file_for_update(journal, std::uintmax_t{1} << 20);
  } catch (const DataError& e) {
    refuse_journal(journal, e.what());
  }
  if (!text) return {};
  if (!text->starts_with(kJournalHeader)) {
    refuse_journal(journal, "does not begin with the format tag \"calligraphy-set-journal 3\"");
  }
  if (!text->ends_with("\n")) refuse_journal(journal, "cut short (no checksum line)");
  const std::size_t checksum_line = text->rfind('\n', text->size() - 2) + 1;
  const std::string_view body(text->data(), checksum_line);
  const std::string_view last(text->data() + checksum_line, text->size() - checksum_line - 1);
  if (!last.starts_with(kJournalChecksum) || checksum_line <= kJournalHeader.size() ||
      last.substr(kJournalChecksum.size()) != journal_checksum(body)) {
    refuse_journal(journal, "its checksum does not match its contents");
  }
  std::vector<JournalEntry> entries;
  std::size_t start = kJournalHeader.size();
  while (start < checksum_line) {
    const std::size_t end_of_line = text->find('\n', start);
    const std::string line = text->substr(start, end_of_line - start);
    start = end_of_line + 1;
    const std::size_t first_tab = line.find('\t');
    const std::size_t second_tab =
        first_tab == std::string::npos ? first_tab : line.find('\t', first_tab + 1);
    if (second_tab == std::string::npos || line.find('\t', second_tab + 1) != std::string::npos ||
        line.find('\0') != std::string::npos) {
      refuse_journal(journal, "a line is not TARGET, KEPT and TEMPORARY");
    }
    const std::string target = line.substr(0, first_tab);
    const std::string kept = line.substr(first_tab + 1, second_tab - first_tab - 1);
    const std::string temporary = line.substr(second_tab + 1);
    std::string quoted("the name \"");
    quoted.append(target).append("\"");
    if (target.empty() || target == "." || target == ".." || target.find('/') != std::string::npos)
      refuse_journal(journal, quoted + " is not the name of a file in the journal's own folder");
    if (!sibling_name(temporary, target, ".tmp-") ||
        (!kept.empty() && !sibling_name(kept, target, ".kept-"))) {
      refuse_journal(journal, quoted + ": its temporary or second name is not one this writer gives");
    }
    JournalEntry entry{folder / target, kept.empty() ? fs::path() : folder / kept, folder / temporary};
    if (!regular_or_absent(entry.target) || !regular_or_absent(entry.temporary) ||
        (!kept.empty() && !regular_or_absent(entry.kept))) {
      refuse_journal(journal, quoted + ": a file it names is a symbolic link or not a regular file");
    }
    entries.push_back(std::move(entry));
  }
  return entries;
}

// Completes every set a killed writer left half replaced in `folders` (held locked): each journal is read
// and checked whole (read_journal), then each temporary it names that is still there is renamed over its
// target, and the earlier files' second names and the journal are removed. The lock says no live writer is
// between its renames. A journal refused throws, naming it, before anything of it is done.
void complete_interrupted_sets(const std::vector<SetFolder>& folders) {
  for (const SetFolder& set_folder : folders) {
    const fs::path& folder = set_folder.folder;
    std::error_code error;
    std::vector<fs::path> journals;
    for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
      const std::string name = entry->path().filename().string();
      if (name.starts_with(kJournalPrefix) && name.ends_with(kJournalSuffix))
        journals.push_back(entry->path());
    }
    std::sort(journals.begin(), journals.end());
    for (const fs::path& journal : journals) {
      const std::vector<JournalEntry> entries = read_journal(journal, folder);
      for (const JournalEntry& entry : entries) {
        // A temporary already renamed is gone (ENOENT); any other failure keeps the journal, so that the set
        // is completed by a later write rather than left half replaced with no record of it.
        if (::rename(entry.temporary.c_str(), entry.target.c_str()) != 0 && errno != ENOENT) {
          const int rename_error = errno;
          std::string what("cannot complete the set it records (the journal is kept for the next write): ");
          what.append(entry.target.string());
          fail(journal, what, rename_error);
        }
      }
      for (const JournalEntry& entry : entries) {
        if (!entry.kept.empty()) ::unlink(entry.kept.c_str());
      }
      ::unlink(journal.c_str());
      sync_folder(journal, journal);
    }
    remove_dead_writers_files(folder);
  }
}

}  // namespace

void remove_dead_temporaries_of(const fs::path& path) { remove_dead_writers_temporaries(path); }

int register_made_folder(const fs::path& folder) noexcept { return claim_slot(made_folder_slots, folder); }

void release_made_folder(int slot) noexcept {
  if (slot >= 0) made_folder_slots[slot].state.store(0);
}

fs::path written_path(const fs::path& path) {
  // What the kernel reaches through the path's links and is not a regular file (a device, a FIFO, or the
  // pipe, socket or terminal behind /dev/stdout, whose /proc/self/fd link reads `pipe:[N]`, no file name) is
  // written in place through the path itself: its links are not followed one by one into a name that is no
  // file, where a dangling link's target would then be created.
  struct stat reached {};
  if (::stat(path.c_str(), &reached) == 0 && !S_ISREG(reached.st_mode)) return path;
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
  remove_dead_writers_temporaries(target);
}

bool write_file_exclusively(const fs::path& path, std::string_view content) {
  if (path.empty()) throw DataError("cannot write a file with an empty name");
  remove_dead_writers_temporaries(path);
  // Written whole to an unnamed file of the folder (O_TMPFILE), synced, then linked to its name through
  // /proc/self/fd: linkat(2) never replaces a name that exists (a file, a link or anything else), and a
  // process stopped at any moment leaves nothing.
  int fd = ::open(folder_of(path).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd >= 0) {
    int error = write_all(fd, content);
    if (error == 0 && ::fsync(fd) != 0) error = errno;
    if (error != 0) {
      ::close(fd);
      fail(path, "cannot write", error);
    }
    std::string proc = "/proc/self/fd/";
    proc.append(std::to_string(fd));
    const int linked = ::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, path.c_str(), AT_SYMLINK_FOLLOW);
    const int link_error = linked == 0 ? 0 : errno;
    const int close_error = close_checked(fd);
    if (linked == 0) {
      if (close_error != 0) fail(path, "written, but closing it failed", close_error);
      sync_folder(path, path);
      return true;
    }
    if (link_error == EEXIST) return false;
    if (link_error != ENOENT) fail(path, "cannot create", link_error);
    // ENOENT: no /proc here; the named temporary below
  }
  // No O_TMPFILE on this file system (or no /proc): a temporary named by this process (O_EXCL | O_NOFOLLOW),
  // written whole and synced, then linked to its name; the temporary is removed on every way out, and what a
  // killed process left is removed by the next write of the name (remove_dead_writers_temporaries).
  TemporaryFile temporary(path, path, 0, false);
  temporary.write(content);
  const int error = temporary.link_to(path);
  if (error == EEXIST) return false;
  if (error != 0) fail(path, "cannot create", error);
  sync_folder(path, path);
  return true;
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
  // A file of a set is written only in its own folder: a symbolic link in a member's place is never
  // followed (it may lead anywhere, e.g. out of a tables folder onto a file of the system) and is refused
  // before anything of the set is replaced. A hard-linked member needs no rule: it is replaced by rename,
  // which gives the name a new file and leaves the file its other names share as it was.
  const fs::path& target = path;
  struct stat status {};
  bool exists = false;
  if (::lstat(target.c_str(), &status) == 0 && S_ISLNK(status.st_mode)) {
    throw DataError(
        path.string() +
        ": is a symbolic link: a file of a set is written only in its own folder, never through a "
        "link (nothing written; remove the link or write the set elsewhere)");
  }
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
  // an exclusive lock of each of its folders, so that two writers of one set never interleave their renames.
  // A set that a killed writer left half replaced in one of these folders is completed first (its journal,
  // above). Then every folder gets its journal, and the set is replaced folder by folder, each folder's
  // journal removed once its renames are done.
  {
    const std::vector<SetFolder> folders = folders_of_set(targets);
    const FolderLocks locks(folders);
    complete_interrupted_sets(folders);
    const RenamesUnderWay renaming;  // a stop signal from here on ends the process once the set is whole
    SetReplacement replacement(targets, impl_->existed);
    for (std::size_t i = 0; i < targets.size(); ++i)
      replacement.add_temporary(i, impl_->temporaries[i]->path());
    replacement.write_journals(folders);
    std::vector<std::size_t> renamed;
    renamed.reserve(targets.size());
    for (std::size_t f = 0; f < folders.size(); ++f) {
      for (const std::size_t i : folders[f].files) {
        try {
          impl_->temporaries[i]->rename_to(targets[i]);
        } catch (const DataError&) {
          replacement.roll_back(renamed);  // the earlier set again, then the error naming the file at fault
          throw;
        }
        renamed.push_back(i);
      }
      replacement.folder_done(f);
    }
    replacement.commit();
  }
  for (const fs::path& target : targets) sync_folder(target, target);
  for (const auto& [path, content] : impl_->in_place) write_in_place(path, content);
}

void guard_output_files() noexcept {
  if (signals_guarded.exchange(true)) return;
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, nullptr);
  sigaction(SIGPIPE, &ignore, nullptr);
  struct sigaction cleanup {};
  cleanup.sa_handler = remove_temporaries_then_die;
  sigemptyset(&cleanup.sa_mask);
  for (const int signal : stop_signal_numbers()) sigaddset(&cleanup.sa_mask, signal);
  cleanup.sa_flags = SA_RESTART;
  for (const int signal : stop_signal_numbers()) {
    struct sigaction current {};
    if (sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_DFL) {
      sigaction(signal, &cleanup, nullptr);
    }
  }
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
