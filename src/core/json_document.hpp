#pragma once
// Parsing a JSON document read from a file (a trial record, a protocol, a teacher's recording): the one
// parse that every reader of the library uses, so that no parser error escapes as anything but a DataError
// naming the file. Internal.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::json_detail {

/// The DataError of a number beyond a double's range, with its JSON pointer and its text ("1e999"), for a
/// reader that knows what the value there means (a record's version) and can say what it expected.
class NumberOverflow : public DataError {
 public:
  NumberOverflow(const std::string& message, std::string pointer, std::string literal)
      : DataError(message), pointer_(std::move(pointer)), literal_(std::move(literal)) {}
  [[nodiscard]] const std::string& pointer() const noexcept { return pointer_; }
  [[nodiscard]] const std::string& literal() const noexcept { return literal_; }

 private:
  std::string pointer_;
  std::string literal_;
};

/// The document `text`. Throws DataError "SOURCE: not valid JSON at byte N: ..." for malformed JSON, and
/// "SOURCE: POINTER: not a finite number: ..." (the JSON pointer of the value) for a number beyond a
/// double's range (1e999, -1e400), which the parser refuses without a byte offset (a NumberOverflow).
nlohmann::json parse_json_document(std::string_view text, const std::string& source);

/// What `text` is, by its first bytes, when it cannot be a JSON document at all: another kind of file the
/// program writes or reads (a trace, a gzip, a corpus store, an HDF5 file, an SVG drawing or HTML page, CSV
/// text) or "binary data"; empty when it begins as JSON may. So that a file given to the wrong reader is
/// named for what it is ("r.csv: not a JSON document: it is CSV text ..."), not by the parser's words for its
/// first byte.
std::string non_json_kind(std::string_view text);

/// nlohmann/json's message for an error without its "[json.exception.parse_error.101] parse error at line 1,
/// column 2: " prefix, which names the parser's own exception (the reader states where).
std::string parser_reason(const std::string& what);

}  // namespace calligraphy::json_detail
