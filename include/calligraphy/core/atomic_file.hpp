#pragma once
/// \file atomic_file.hpp
/// Writing output files so that nothing is lost: a reader sees either the earlier file or the whole new
/// one, never a truncated mix, and a failure is an exception naming the file, never a silent short write.
///
/// For a regular file (or a path that does not exist yet) the content goes to a temporary file in the same
/// folder, is written completely (every write checked, interrupted and short writes resumed), fsync'ed,
/// closed (checked) and renamed over the target (rename(2) replaces a file atomically within one file
/// system, POSIX.1-2017); the folder is then fsync'ed so that the rename itself is durable. A symbolic link
/// keeps pointing where it did: the file it points to is replaced, and a dangling link's target is created
/// (the link is never replaced by a regular file; see `written_path`). The new file gets the earlier file's
/// permission bits, or 0666 less the umask for a new file; an earlier file the caller may not write
/// (access(2) W_OK) is refused rather than replaced. On failure the temporary is removed and the earlier
/// file is untouched.
///
/// A target that exists but is not a regular file (a character device such as /dev/null or /dev/full, a
/// FIFO, a terminal) cannot be replaced by a rename: it is opened for writing as it is and written
/// directly, and every write and the close are checked.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace calligraphy {

/// Writes `content` to `path` as described in the file comment. Throws DataError naming `path` and the
/// system's reason (e.g. "No space left on device", "Permission denied", "Is a directory") when any step
/// fails: the folder cannot hold a temporary file, a write, fsync, close or the rename fails.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

/// Creates `path` with `content`, never replacing anything: the content is written whole and fsync'ed in an
/// unnamed file of the folder (O_TMPFILE; where the file system has none, a temporary named by this process,
/// created with O_EXCL | O_NOFOLLOW), then linked to its name (linkat(2), which fails rather than replace a
/// file, a symbolic link or a folder there), and the folder is fsync'ed. Returns true when it made the file,
/// false when `path` existed already (nothing written: a file another writer made first is kept, so of two
/// writers racing, the second reads the first one's). A process stopped at any moment leaves no partial file
/// under `path`: at worst a named temporary, which the next call for `path` removes once its process is gone.
/// Permissions: 0666 less the umask. Throws DataError naming `path` and the system's reason when a step fails
/// (the folder is missing or read-only, the disk is full): a failed write is an error, and leaves no file.
[[nodiscard]] bool write_file_exclusively(const std::filesystem::path& path, std::string_view content);

/// Removes the named temporaries that killed writers of `path` left beside it (".NAME.tmp-PID-N", their
/// process gone), as the writers above do before they write: for a caller that finds `path` made and writes
/// nothing.
void remove_dead_temporaries_of(const std::filesystem::path& path);

/// The path a write to `path` replaces or creates: symbolic links followed one by one (a relative target
/// read from the link's folder), a dangling link to the path it names, any other path as it is; a path that
/// reaches something other than a regular file (a device, a FIFO, /dev/stdout on a pipe) as it is. Throws
/// DataError naming `path` when a link cannot be read or there are more than 40 links in a chain (ELOOP).
[[nodiscard]] std::filesystem::path written_path(const std::filesystem::path& path);

/// One file of a set written together.
struct FileContent {
  std::filesystem::path path;
  std::string_view content;
};

/// A set of files that belong together (a study's tables, a report's pages), written so that a reader and a
/// later run find the earlier set or the whole new one:
///  - `add` writes one file's temporary beside its target, whole (fsync'ed and closed), so that a large set
///    need not be held in memory; a failure (a full disk) throws and, once the set is destroyed, leaves every
///    earlier file as it was. `add` may be called from several threads.
///  - `commit` replaces the targets under an exclusive flock(2) of each of their folders (two writers of one
///    set never interleave), folder by folder in the sorted order of the folders, one rename each in the
///    order added within a folder. Before the first rename each earlier file gets a second name (a hard link
///    beside it), so that a rename failing part way (EIO, an immutable file) puts every replaced file back,
///    in every folder, and throws naming the file at fault. Each folder of the set gets its own journal
///    (`.calligraphy-set-*.journal`), written whole and synced before the set's first rename and removed once
///    that folder's renames are done; it names only files in its own folder. A writer killed part way leaves
///    each folder either replaced or holding its journal, and the next set committed in a folder first
///    completes that folder's journal from the whole temporaries. So "replaced together" means: within one
///    folder, the earlier files, the new ones, or a mix its journal records and the next set there completes;
///    across folders, a set killed part way (also while its journals were being written) may leave some
///    folders new and others earlier, each folder whole or journalled on its own, until a later set in each
///    (the same command run again) completes it. The
///    journal holds its format tag and version, file names and a checksum of its contents; one that differs
///    in any of them, names a file with a "/" (or ".", ".."), or names a symbolic link, is refused before
///    anything is done: the commit throws DataError naming the journal, which is left as it is. So a journal
///    copied with its folder completes the copy only, and one planted in a folder changes nothing outside it.
///    A set needs no folder but its targets' own (in which `add` already made the temporaries); a stop
///    signal (guard_output_files) that comes between the first and the last rename ends the process once
///    the set is whole.
///  - a set is written only in its own folders, never through a link: a target that is a symbolic link
///    (dangling or not) is refused by `add` (DataError naming it) before anything of the set is replaced,
///    unlike `write_file_atomically`, which writes the file one link names; a link planted after `add` is
///    replaced by the rename, its target untouched. A target with other hard links is replaced by rename
///    too: the name gets the new file, and the file its other names share is left as it was.
///  - destroyed without `commit`: the temporaries are removed and no target changes.
/// Throws DataError naming the file at fault (as `write_file_atomically`), StateError for `add` after
/// `commit` or a second `commit`. A device or FIFO among the targets is written in place after the renames.
class AtomicFileSet {
 public:
  AtomicFileSet();
  ~AtomicFileSet();
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;
  /// Writes the temporary of `path` (see the class comment).
  void add(const std::filesystem::path& path, std::string_view content);
  /// Replaces every target added (see the class comment).
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Makes a program's file outputs safe from the signals that would otherwise end it mid-write; call once at
/// start-up, before any thread is made (the command line's main does):
///  - SIGXFSZ is ignored, so a write over the file size limit (RLIMIT_FSIZE, `ulimit -f`) fails with EFBIG,
///    which the writers report (DataError naming the file) after removing their temporary;
///  - SIGPIPE is ignored, so a closed pipe is the write error EPIPE, reported, not a silent death;
///  - the stop signals (stop_signals.hpp: SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGUSR2, SIGXCPU), where they are
///    at their default action, first remove every temporary file the writers of this file have open, then
///    end the process as the default action would (a set between its renames is finished first). A program
///    that catches them itself (StopSignals, while it lives) is not changed. Never throws.
void guard_output_files() noexcept;

/// A folder a command made for its outputs (a report's page folders), removed by a stop signal that ends the
/// process while it is registered, after the temporaries (guard_output_files: rmdir(2), so only while empty,
/// deepest first): a command stopped leaves no folder of its own, as a command that fails removes the folders
/// it made. Returns the registration's slot, or -1 when it cannot be held (a path of PATH_MAX bytes or more,
/// or 256 folders registered at once: that folder is then left by a signal). Never throws, never allocates.
int register_made_folder(const std::filesystem::path& folder) noexcept;
/// Ends the registration `slot` of `register_made_folder` (-1: none), once the folder is kept or removed.
void release_made_folder(int slot) noexcept;

/// The files of `files` as one `AtomicFileSet`, committed.
void write_files_atomically(std::span<const FileContent> files);

/// The same for binary content (e.g. an encoded corpus store).
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> content);

/// Largest file `read_file_for_update` reads by default: 64 MiB, far above any document it updates.
inline constexpr std::uintmax_t kMaxUpdatedFileBytes = std::uintmax_t{64} << 20;

/// The content of an existing regular file that is about to be rewritten with parts of it kept (a
/// document whose generated section is replaced). nullopt when `path` does not exist or is not a regular
/// file: nothing is ever read from a device or FIFO (/dev/zero would never end). Throws DataError naming
/// the path when it cannot be read or is larger than `max_bytes`.
std::optional<std::string> read_file_for_update(const std::filesystem::path& path,
                                                std::uintmax_t max_bytes = kMaxUpdatedFileBytes);

}  // namespace calligraphy
