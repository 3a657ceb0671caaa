#include "report/compressed_text.hpp"

#include <zlib.h>

#include <algorithm>
#include <climits>

#include "calligraphy/core/errors.hpp"
#include "core/whole_file.hpp"

namespace calligraphy {
namespace {

gzFile handle(void* file) { return static_cast<gzFile>(file); }

}  // namespace

std::string gzip_text(std::string_view text) {
  z_stream stream{};
  // 15 window bits + 16: a gzip header and trailer instead of zlib's (zlib.h, deflateInit2).
  if (deflateInit2(&stream, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw DataError("gzip: zlib cannot start compressing");
  }
  std::string out(deflateBound(&stream, static_cast<uLong>(text.size())), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  stream.avail_in = static_cast<uInt>(text.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  const int result = deflate(&stream, Z_FINISH);
  const std::size_t written = stream.total_out;
  deflateEnd(&stream);
  if (result != Z_STREAM_END || text.size() > UINT_MAX) {
    throw DataError("gzip: zlib could not compress " + std::to_string(text.size()) + " bytes");
  }
  out.resize(written);
  return out;
}

std::string gunzip_text(std::string_view bytes, const std::string& source, std::uintmax_t max_text_bytes) {
  const auto is_gzip = [](std::string_view b) { return b.size() >= 2 && b[0] == '\x1f' && b[1] == '\x8b'; };
  if (!is_gzip(bytes)) {
    if (bytes.size() > max_text_bytes) {
      throw DataError(source + ": more than " + std::to_string(max_text_bytes) +
                      " bytes of text, the limit (the rest is not read)");
    }
    return std::string(bytes);
  }
  std::string text;
  constexpr std::size_t kBlockBytes = std::size_t{1} << 18;
  while (is_gzip(bytes)) {  // one gzip member a turn
    z_stream stream{};
    if (inflateInit2(&stream, 15 + 16) != Z_OK)
      throw DataError(source + ": cannot be read (gzip: out of memory)");
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    stream.avail_in = static_cast<uInt>(std::min<std::size_t>(bytes.size(), UINT_MAX));
    int result = Z_OK;
    while (result != Z_STREAM_END) {
      const std::size_t kept = text.size();
      text.resize(kept + kBlockBytes);
      stream.next_out = reinterpret_cast<Bytef*>(text.data() + kept);
      stream.avail_out = static_cast<uInt>(kBlockBytes);
      result = inflate(&stream, Z_NO_FLUSH);
      text.resize(kept + kBlockBytes - stream.avail_out);
      const bool stuck =
          result == Z_BUF_ERROR || (result == Z_OK && stream.avail_in == 0 && stream.avail_out != 0);
      if (result != Z_OK && result != Z_STREAM_END && !stuck) {
        const std::string message = stream.msg != nullptr ? stream.msg : "damaged stream";
        inflateEnd(&stream);
        throw DataError(source + ": cannot be read (gzip: " + message + ")");
      }
      if (stuck) {  // the input ended inside the member
        inflateEnd(&stream);
        throw DataError(source + ": cannot be read (gzip: unexpected end of file)");
      }
      if (text.size() > max_text_bytes) {
        inflateEnd(&stream);
        throw DataError(source + ": more than " + std::to_string(max_text_bytes) +
                        " bytes of text, the limit (the rest is not read)");
      }
    }
    bytes.remove_prefix(bytes.size() - stream.avail_in);
    inflateEnd(&stream);
  }
  return text;
}

TextFileReader::TextFileReader(const std::filesystem::path& file, std::uintmax_t max_file_bytes,
                               std::uintmax_t max_text_bytes)
    : name_(file.string()), max_text_bytes_(max_text_bytes) {
  file_bytes_ = regular_file_size(file, max_file_bytes);
  file_ = gzopen(name_.c_str(), "rb");  // reads a file that is not gzip as it is (zlib.h, gzopen)
  if (file_ == nullptr) throw DataError(name_ + ": cannot be opened");
  gzbuffer(handle(file_), 256 * 1024);
}

TextFileReader::~TextFileReader() {
  if (file_ != nullptr) gzclose_r(handle(file_));
}

std::size_t TextFileReader::read(char* out, std::size_t size) {
  const int got = gzread(handle(file_), out, static_cast<unsigned>(std::min<std::size_t>(size, INT_MAX)));
  int error = Z_OK;
  const char* message = gzerror(handle(file_), &error);
  // A gzip stream cut short reads to its end, then reports Z_BUF_ERROR ("unexpected end of file").
  if (got < 0 || (error != Z_OK && error != Z_STREAM_END)) {
    throw DataError(name_ + ": cannot be read (" + (gzdirect(handle(file_)) ? "" : "gzip: ") + message + ")");
  }
  text_bytes_ += static_cast<std::uintmax_t>(got);
  if (text_bytes_ > max_text_bytes_) {
    throw DataError(name_ + ": more than " + std::to_string(max_text_bytes_) +
                    " bytes of text, the limit (the rest is not read)");
  }
  return static_cast<std::size_t>(got);
}

std::uintmax_t TextFileReader::file_offset() const {
  const z_off_t offset = gzoffset(handle(file_));
  return offset < 0 ? 0 : static_cast<std::uintmax_t>(offset);
}

void for_each_line(TextFileReader& reader, const std::string& source, std::size_t max_line_bytes,
                   const std::function<void(std::string_view line)>& line) {
  constexpr std::size_t kBlockBytes = std::size_t{1} << 18;
  std::string buffer;  // an unfinished line, then the next block
  std::size_t line_number = 0;
  while (true) {
    const std::size_t kept = buffer.size();
    buffer.resize(kept + kBlockBytes);
    const std::size_t got = reader.read(buffer.data() + kept, kBlockBytes);
    buffer.resize(kept + got);
    if (got == 0) break;
    std::size_t start = 0;
    for (std::size_t newline; (newline = buffer.find('\n', start)) != std::string::npos;
         start = newline + 1) {
      ++line_number;
      line(std::string_view(buffer).substr(start, newline - start));
    }
    buffer.erase(0, start);
    if (buffer.size() > max_line_bytes) {
      throw DataError(source + ":" + std::to_string(line_number + 1) + ": a line longer than " +
                      std::to_string(max_line_bytes) + " bytes");
    }
  }
  if (!buffer.empty()) line(buffer);
}

}  // namespace calligraphy
