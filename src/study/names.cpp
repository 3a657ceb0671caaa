#include "study/names.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/session_folder.hpp"

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
  if (error || !std::filesystem::exists(status)) {
    throw DataError(path.string() + ": no such file (expected a " + what + ")");
  }
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

double utc_seconds(std::string_view iso8601) {
  const std::string text(iso8601);
  std::tm utc{};
  int consumed = 0;
  const int fields = std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &utc.tm_year, &utc.tm_mon,
                                 &utc.tm_mday, &utc.tm_hour, &utc.tm_min, &utc.tm_sec, &consumed);
  std::string_view rest = iso8601.substr(static_cast<std::size_t>(fields == 6 ? consumed : 0));
  double fraction = 0.0;
  if (fields == 6 && rest.size() > 1 && rest.front() == '.') {
    std::size_t digits = 1;
    double scale = 0.1;
    while (digits < rest.size() && rest[digits] >= '0' && rest[digits] <= '9') {
      fraction += scale * (rest[digits] - '0');
      scale /= 10.0;
      ++digits;
    }
    rest.remove_prefix(digits);
  }
  if (fields != 6 || rest != "Z" || utc.tm_mon < 1 || utc.tm_mon > 12 || utc.tm_mday < 1 ||
      utc.tm_mday > 31) {
    throw InvalidArgument("'" + text + "' is not a UTC time like 2024-05-01T12:34:56.789Z");
  }
  utc.tm_year -= 1900;
  utc.tm_mon -= 1;
  return static_cast<double>(timegm(&utc)) + fraction;
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
