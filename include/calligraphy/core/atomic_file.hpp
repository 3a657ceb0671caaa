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
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace calligraphy {

/// Writes `content` to `path` as described in the file comment. Throws DataError naming `path` and the
/// system's reason (e.g. "No space left on device", "Permission denied", "Is a directory") when any step
/// fails: the folder cannot hold a temporary file, a write, fsync, close or the rename fails.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

/// The path a write to `path` replaces or creates: symbolic links followed one by one (a relative target
/// read from the link's folder), a dangling link to the path it names, any other path as it is. Throws
/// DataError naming `path` when a link cannot be read or there are more than 40 links in a chain (ELOOP).
[[nodiscard]] std::filesystem::path written_path(const std::filesystem::path& path);

/// One file of a set written together.
struct FileContent {
  std::filesystem::path path;
  std::string_view content;
};

/// Writes a set of files that belong together (a study's tables): every file's temporary is written whole,
/// fsync'ed and closed first; only then are the targets replaced, one rename each, in the given order,
/// under an exclusive flock(2) of their folders, so that two processes writing the same set leave one
/// writer's whole set, never a mix of both. A
/// failure while writing (e.g. a full disk) removes every temporary and leaves every earlier file as it
/// was, so a reader never finds a new file beside an old one of the set. (Between the renames, which need
/// no space, only a crash of the machine or the process can leave part of the set replaced.) Throws
/// DataError naming the file at fault, as `write_file_atomically`.
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
