#include "study/names.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "core/json_reader.hpp"
#include "core/utc_time.hpp"
#include "core/whole_file.hpp"

namespace calligraphy::study_detail {

bool is_label(std::string_view text, std::size_t max_length) {
  if (text.empty() || text.size() > max_length) return false;
  for (const char c : text) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

bool is_study_id(std::string_view text) {
  if (text.size() != 32) return false;
  for (const char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

std::string read_small_file(const std::filesystem::path& path, std::uintmax_t max_bytes,
                            const std::string& what) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw missing_input(path, error, "a " + what);
  if (!std::filesystem::is_regular_file(status)) {
    throw DataError(path.string() + ": not a regular file (expected a " + what + ")");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > max_bytes) {
    throw DataError(path.string() + ": " + std::to_string(size) + " bytes, more than the " +
                    std::to_string(max_bytes) + " a " + what + " may have");
  }
  std::optional<std::string> text = read_file_for_update(path, max_bytes);
  if (!text) throw DataError(path.string() + ": cannot be read (expected a " + what + ")");
  return std::move(*text);
}

std::string session_file_link_message(const std::filesystem::path& path) {
  return path.string() +
         ": is a symbolic link; a session's files are its own: put the file itself back in its place "
         "(nothing "
         "is read or written through a link in a session folder)";
}

std::string read_session_file(const std::filesystem::path& path, std::uintmax_t max_bytes,
                              const std::string& what) {
  // O_NOFOLLOW: a link under the file's name is refused, not followed (open(2): ELOOP); O_NONBLOCK: a FIFO
  // planted there is refused below without waiting for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    struct stat link {};
    if (error == ELOOP && ::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode))
      throw DataError(session_file_link_message(path));
    if (error == ENOENT) throw no_such_file(path, "a " + what);
    throw DataError(path.string() + ": cannot be opened (" + std::strerror(error) + "; expected a " + what +
                    ")");
  }
  std::string text;
  try {
    struct stat status {};
    if (::fstat(fd, &status) != 0)
      throw DataError(path.string() + ": cannot be read (expected a " + what + ")");
    if (!S_ISREG(status.st_mode))
      throw DataError(path.string() + ": not a regular file (expected a " + what + ")");
    const auto size = static_cast<std::uintmax_t>(status.st_size);
    if (size > max_bytes) {
      throw DataError(path.string() + ": " + std::to_string(size) + " bytes, more than the " +
                      std::to_string(max_bytes) + " a " + what + " may have");
    }
    text.resize(static_cast<std::size_t>(size));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t got = ::read(fd, text.data() + done, text.size() - done);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) throw DataError(path.string() + ": could not be read whole (expected a " + what + ")");
      done += static_cast<std::size_t>(got);
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return text;
}

double utc_seconds_of(std::string_view iso8601, const std::string& source, std::string_view pointer) {
  try {
    return utc_seconds(iso8601);
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, std::string(pointer), e.what());
  }
}

// Names in order with each run of digits read as a number, so that a subject's sessions come in the order
// they began: the second's "-2" ... "-10" suffixes too (made in one second; "-10" sorts before "-2" as text).
bool natural_less(const std::string& x, const std::string& y) {
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  std::size_t i = 0, j = 0;
  while (i < x.size() && j < y.size()) {
    if (digit(x[i]) && digit(y[j])) {
      std::size_t end_i = i, end_j = j;
      while (end_i < x.size() && digit(x[end_i])) ++end_i;
      while (end_j < y.size() && digit(y[end_j])) ++end_j;
      std::size_t zi = i, zj = j;  // leading zeros do not count toward the value
      while (zi + 1 < end_i && x[zi] == '0') ++zi;
      while (zj + 1 < end_j && y[zj] == '0') ++zj;
      const std::string_view u(x.data() + zi, end_i - zi), v(y.data() + zj, end_j - zj);
      if (u.size() != v.size()) return u.size() < v.size();
      if (u != v) return u < v;
      if (end_i - i != end_j - j) return end_i - i < end_j - j;
      i = end_i;
      j = end_j;
    } else {
      if (x[i] != y[j]) return static_cast<unsigned char>(x[i]) < static_cast<unsigned char>(y[j]);
      ++i;
      ++j;
    }
  }
  return x.size() - i < y.size() - j;
}

// Paths element by element in natural_less order of their names.
bool session_path_less(const std::filesystem::path& a, const std::filesystem::path& b) {
  return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(),
                                      [](const std::filesystem::path& x, const std::filesystem::path& y) {
                                        return natural_less(x.native(), y.native());
                                      });
}

std::uint64_t fnv1a_64(std::string_view text) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;  // offset basis
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;  // FNV prime
  }
  return hash;
}

std::uint64_t mix64(std::uint64_t value) {
  value += 0x9e3779b97f4a7c15ULL;
  value = (value ^ (value >> 30)) * 0xbf58476d1ce4e5b9ULL;
  value = (value ^ (value >> 27)) * 0x94d049bb133111ebULL;
  return value ^ (value >> 31);
}

}  // namespace calligraphy::study_detail

namespace calligraphy {

std::string utc_now_iso8601() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto milliseconds =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[96];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(milliseconds));
  return text;
}

}  // namespace calligraphy
