#pragma once
// Parsing a JSON document read from a file (a trial record, a protocol, a teacher's recording): the one
// parse that every reader of the library uses, so that no parser error escapes as anything but a DataError
// naming the file. Internal.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace calligraphy::json_detail {

/// The document `text`. Throws DataError "SOURCE: not valid JSON at byte N: ..." for malformed JSON, and
/// "SOURCE: POINTER: not a finite number: ..." (the JSON pointer of the value) for a number beyond a
/// double's range (1e999, -1e400), which the parser refuses without a byte offset.
nlohmann::json parse_json_document(std::string_view text, const std::string& source);

}  // namespace calligraphy::json_detail
