#include "core/whole_file.hpp"

#include <sys/stat.h>

#include <fstream>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

std::uintmax_t regular_file_size(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw DataError(name + ": no such file");
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
  const std::uintmax_t size = regular_file_size(path, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DataError(name + ": cannot be opened");
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) throw DataError(name + ": could not be read whole");
  return text;
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
