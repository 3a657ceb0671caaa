#include "eval/generated_document.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::cli {

namespace {

std::string quoted(const std::string& path) { return "'" + path + "'"; }

}  // namespace

std::string read_generated_document(const std::string& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // follows symbolic links
  if (status.type() == fs::file_type::not_found) return {};
  if (error) {
    throw Error("cannot inspect the Markdown file " + quoted(path) + ": " + error.message());
  }
  // Checked before opening: a FIFO would block in open, a device like /dev/zero never ends.
  if (status.type() != fs::file_type::regular) {
    throw InvalidArgument("the Markdown file " + quoted(path) +
                          " is not a regular file; --markdown expects a Markdown document to update");
  }
  const std::uintmax_t size = fs::file_size(path, error);
  const std::string too_large = "the Markdown file " + quoted(path) + " is larger than " +
                                std::to_string(max_bytes) + " bytes, the limit for a document to update";
  if (!error && size > max_bytes) throw InvalidArgument(too_large);

  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the Markdown file " + quoted(path) + " for reading");
  // At most max_bytes + 1 bytes, whatever the size said: the file may grow while it is read.
  std::string content;
  std::vector<char> buffer(64 * 1024);
  while (content.size() <= max_bytes) {
    const std::uintmax_t wanted = std::min<std::uintmax_t>(buffer.size(), max_bytes + 1 - content.size());
    in.read(buffer.data(), static_cast<std::streamsize>(wanted));
    const std::streamsize got = in.gcount();
    content.append(buffer.data(), static_cast<std::size_t>(got));
    if (!in) break;
  }
  if (content.size() > max_bytes) throw InvalidArgument(too_large);
  if (in.bad()) throw Error("cannot read the Markdown file " + quoted(path));
  return content;
}

}  // namespace calligraphy::cli
