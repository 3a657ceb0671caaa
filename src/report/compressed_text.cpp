#include "report/compressed_text.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "core/whole_file.hpp"

namespace calligraphy {
namespace {

bool starts_gzip(const unsigned char* bytes, std::size_t size) {
  return size >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
}

// Bytes after the last member that start no other member: gunzip's "trailing garbage", refused.
DataError bytes_after_gzip(const std::string& source, std::uintmax_t offset, std::uintmax_t count) {
  return DataError(source + ": cannot be read (gzip: " + std::to_string(count) + " bytes at byte " +
                   std::to_string(offset) + ", after its last member, start no gzip member)");
}

}  // namespace

struct TextFileReader::State {
  std::FILE* file = nullptr;  // null: the bytes were given in memory, `input` points at them
  bool gzip = false;
  bool done = false;  // a gzip file's last member has ended at the end of the file
  z_stream stream{};
  bool inflating = false;                // `stream` initialised
  std::vector<unsigned char> buffer;     // a file's bytes as read
  const unsigned char* input = nullptr;  // `buffer`, or the bytes given; [used, filled) not yet taken
  std::size_t used = 0, filled = 0;
  std::uintmax_t read_from_file = 0;  // bytes in all
  bool end_of_file = false;

  State() = default;
  State(const State&) = delete;
  State& operator=(const State&) = delete;
  ~State() {
    if (inflating) inflateEnd(&stream);
    if (file != nullptr) std::fclose(file);
  }

  // At least `want` bytes not yet taken, unless the file ends first (bytes given in memory have ended).
  void refill(const std::string& name, std::size_t want) {
    if (filled - used >= want || end_of_file) return;
    std::memmove(buffer.data(), buffer.data() + used, filled - used);
    filled -= used;
    used = 0;
    while (filled < want && !end_of_file) {
      const std::size_t got = std::fread(buffer.data() + filled, 1, buffer.size() - filled, file);
      filled += got;
      read_from_file += got;
      if (got == 0) {
        if (std::ferror(file) != 0) throw DataError(name + ": cannot be read (" + std::strerror(errno) + ")");
        end_of_file = true;
      }
    }
  }
};

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
  TextFileReader reader(bytes, source, max_text_bytes);
  std::string text;
  constexpr std::size_t kBlockBytes = std::size_t{1} << 18;
  while (true) {
    const std::size_t kept = text.size();
    text.resize(kept + kBlockBytes);
    const std::size_t got = reader.read(text.data() + kept, kBlockBytes);
    text.resize(kept + got);
    if (got == 0) return text;
  }
}

TextFileReader::TextFileReader(const std::filesystem::path& file, std::uintmax_t max_file_bytes,
                               std::uintmax_t max_text_bytes)
    : name_(file.string()), state_(std::make_unique<State>()), max_text_bytes_(max_text_bytes) {
  file_bytes_ = regular_file_size(file, max_file_bytes);
  State& s = *state_;
  s.file = std::fopen(name_.c_str(), "rb");
  if (s.file == nullptr) throw DataError(name_ + ": cannot be opened");
  s.buffer.resize(256 * 1024);
  s.input = s.buffer.data();
  s.refill(name_, 2);
  start();
}

TextFileReader::TextFileReader(std::string_view bytes, std::string source, std::uintmax_t max_text_bytes)
    : name_(std::move(source)), state_(std::make_unique<State>()), max_text_bytes_(max_text_bytes) {
  file_bytes_ = bytes.size();
  State& s = *state_;
  s.input = reinterpret_cast<const unsigned char*>(bytes.data());
  s.filled = bytes.size();
  s.read_from_file = bytes.size();
  s.end_of_file = true;
  start();
}

void TextFileReader::start() {
  State& s = *state_;
  s.gzip = starts_gzip(s.input, s.filled);
  if (s.gzip) {
    // 15 window bits + 16: a gzip member (zlib.h, inflateInit2); inflateReset for each further one.
    if (inflateInit2(&s.stream, 15 + 16) != Z_OK)
      throw DataError(name_ + ": cannot be read (gzip: out of memory)");
    s.inflating = true;
  }
}

TextFileReader::~TextFileReader() = default;

std::size_t TextFileReader::read(char* out, std::size_t size) {
  State& s = *state_;
  size = std::min<std::size_t>(size, UINT_MAX);
  std::size_t got = 0;
  if (!s.gzip) {
    s.refill(name_, 1);
    got = std::min(size, s.filled - s.used);
    std::memcpy(out, s.input + s.used, got);
    s.used += got;
  }
  while (s.gzip && got == 0 && !s.done && size > 0) {
    s.refill(name_, 1);
    s.stream.next_in = const_cast<Bytef*>(s.input + s.used);  // zlib's next_in is not const (zlib.h)
    s.stream.avail_in = static_cast<uInt>(std::min<std::size_t>(s.filled - s.used, UINT_MAX));
    s.stream.next_out = reinterpret_cast<Bytef*>(out);
    s.stream.avail_out = static_cast<uInt>(size);
    const int result = inflate(&s.stream, Z_NO_FLUSH);
    s.used = s.filled - s.stream.avail_in;
    got = size - s.stream.avail_out;
    if (result == Z_STREAM_END) {
      // A member ended: another may follow (RFC 1952, 2.2: `cat a.gz b.gz`), or the file ends here.
      s.refill(name_, 2);
      const std::size_t left = s.filled - s.used;
      if (left == 0) {
        s.done = true;
      } else if (starts_gzip(s.input + s.used, left)) {
        inflateReset(&s.stream);
      } else {
        const std::uintmax_t offset = s.read_from_file - left;
        throw bytes_after_gzip(name_, offset, file_bytes_ > offset ? file_bytes_ - offset : left);
      }
    } else if (result == Z_BUF_ERROR) {  // no progress: the file ended inside a member
      throw DataError(name_ + ": cannot be read (gzip: unexpected end of file)");
    } else if (result != Z_OK) {
      throw DataError(name_ + ": cannot be read (gzip: " +
                      (s.stream.msg != nullptr ? s.stream.msg : "damaged stream") + ")");
    }
  }
  text_bytes_ += static_cast<std::uintmax_t>(got);
  if (text_bytes_ > max_text_bytes_) {
    throw DataError(name_ + ": more than " + std::to_string(max_text_bytes_) +
                    " bytes of text, the limit (the rest is not read)");
  }
  return got;
}

std::uintmax_t TextFileReader::file_offset() const {
  return state_->read_from_file - (state_->filled - state_->used);
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
