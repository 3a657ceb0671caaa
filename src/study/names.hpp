#pragma once
// Names, files and seeds of the study module. Internal.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace calligraphy::study_detail {

/// True for 1..max_length characters from [A-Za-z0-9_-] (safe in file names on every system).
bool is_label(std::string_view text, std::size_t max_length);

/// True for a study folder's id (StudyIdentity): 32 lower-case hex digits.
bool is_study_id(std::string_view text);

/// The bytes of a regular file of at most `max_bytes`. Throws DataError naming the path and `what` it
/// should hold when it does not exist, is not a regular file, is larger or cannot be read.
std::string read_small_file(const std::filesystem::path& path, std::uintmax_t max_bytes,
                            const std::string& what);

/// The bytes of a regular file of a session folder (its session.json, a trial record, its log) of at most
/// `max_bytes`, opened without following a link (O_NOFOLLOW) and without waiting on a FIFO: a file of a
/// session is its own. Throws DataError naming the path (session_file_link_message for a symbolic link) and
/// `what` it should hold when it does not exist, is a link, is not a regular file, is larger or cannot be
/// read whole.
std::string read_session_file(const std::filesystem::path& path, std::uintmax_t max_bytes,
                              const std::string& what);
/// "PATH: is a symbolic link; a session's files are its own: ...".
std::string session_file_link_message(const std::filesystem::path& path);

/// utc_seconds (core/utc_time.hpp) of a file's value at a JSON pointer (a record's /end_time_utc,
/// session.json's /created_utc): one that is not such a time is an InputError naming `source` and `pointer`
/// (json_detail::fail).
double utc_seconds_of(std::string_view iso8601, const std::string& source, std::string_view pointer);

/// Names in order with each run of digits read as a number ("S-2" before "S-10"), leading zeros aside.
bool natural_less(const std::string& x, const std::string& y);
/// Paths element by element in natural_less order of their names: session folders in the order they began.
bool session_path_less(const std::filesystem::path& a, const std::filesystem::path& b);

/// 64-bit FNV-1a of `text` (Fowler, Noll & Vo; IETF draft-eastlake-fnv): a stable seed from a name.
std::uint64_t fnv1a_64(std::string_view text);
/// SplitMix64's finaliser (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number generators",
/// OOPSLA): mixes a 64-bit value into a well-spread one.
std::uint64_t mix64(std::uint64_t value);

}  // namespace calligraphy::study_detail
