#pragma once
// Text files stored gzip-compressed (RFC 1952, through zlib) or plain, read a block at a time: the pen
// traces of trials saved before traces were HDF5 (`NNN-....csv.gz`, or plain `.csv` earlier still). Internal.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace calligraphy {

/// `text` in the gzip format (RFC 1952: deflate, RFC 1951, at zlib's level 6, no file name and no time in
/// the header, so the same text gives the same bytes), as `zcat`, Python's gzip and pandas read it.
/// Throws DataError when zlib fails (out of memory).
[[nodiscard]] std::string gzip_text(std::string_view text);

/// The text of gzip `bytes` (RFC 1952; members one after another are one text, as gunzip reads them), or
/// `bytes` as they are when they do not start as gzip (1f 8b). Bytes after a member that start no other are
/// refused (gunzip's "trailing garbage"): a damaged or plain-text chunk appended to a trace would otherwise
/// be left out without a word. For a file already read whole: the same text as TextFileReader
/// gives. Throws DataError naming `source` for a damaged or truncated stream, or text longer than
/// `max_text_bytes` (refused as soon as the inflated text passes it).
[[nodiscard]] std::string gunzip_text(std::string_view bytes, const std::string& source,
                                      std::uintmax_t max_text_bytes);

/// A text file read a block at a time, decompressed on the way when it is gzip (by its first two bytes,
/// 1f 8b; every member, and nothing after the last one, as gunzip_text), as it is otherwise. Memory holds
/// one block, never the file.
class TextFileReader {
 public:
  /// Opens `file`. Throws DataError naming it when it does not exist, is not a regular file, is larger
  /// than `max_file_bytes` on disk or cannot be opened.
  TextFileReader(const std::filesystem::path& file, std::uintmax_t max_file_bytes,
                 std::uintmax_t max_text_bytes);
  /// Reads `bytes` already in memory (not copied: they outlive the reader), named `source` in errors;
  /// gunzip_text reads through this.
  TextFileReader(std::string_view bytes, std::string source, std::uintmax_t max_text_bytes);
  ~TextFileReader();
  TextFileReader(const TextFileReader&) = delete;
  TextFileReader& operator=(const TextFileReader&) = delete;

  /// Up to `size` bytes of text into `out`; 0 at the end of the text. Throws DataError naming the file for
  /// a damaged or truncated gzip stream, bytes after its last member, a read error, or text longer than
  /// `max_text_bytes` (a small file that decompresses to more is refused, not read).
  std::size_t read(char* out, std::size_t size);

  [[nodiscard]] std::uintmax_t file_bytes() const { return file_bytes_; }  ///< its size on disk
  /// How far into the file (on disk) reading has come, for a progress display.
  [[nodiscard]] std::uintmax_t file_offset() const;

 private:
  void start();  // after the first bytes are in: gzip or not, and the inflater for gzip
  struct State;  // the open file, its unread bytes and the inflater (compressed_text.cpp)
  std::string name_;
  std::unique_ptr<State> state_;
  std::uintmax_t file_bytes_ = 0;
  std::uintmax_t max_text_bytes_ = 0;
  std::uintmax_t text_bytes_ = 0;
};

/// Calls `line` with each line of the reader's text in turn, without its LF (a last line without one
/// too). Lines longer than `max_line_bytes` are refused (DataError naming the file and line number) so
/// that a file without line breaks is not held whole.
void for_each_line(TextFileReader& reader, const std::string& source, std::size_t max_line_bytes,
                   const std::function<void(std::string_view line)>& line);

}  // namespace calligraphy
