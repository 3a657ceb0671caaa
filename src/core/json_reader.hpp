#pragma once
// Strict reading of the JSON documents the library reads (trial specifications, protocols, session manifests,
// trial records): every error names the source (a file) and the JSON pointer (RFC 6901) of the value at
// fault. In `core` because the trial's specification and the study's files read alike. Internal.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>

namespace calligraphy::json_detail {

/// Throws DataError "SOURCE: POINTER: MESSAGE" (the pointer "/" for the document itself).
[[noreturn]] void fail(const std::string& source, const std::string& pointer, const std::string& message);

/// Parses `text` (parse_json_document); throws DataError naming the source and the byte
/// offset of malformed JSON, or the JSON pointer of a number beyond a double's range.
nlohmann::json parse_json(std::string_view text, const std::string& source);

/// A short rendering of a value for messages: "0", "\"latin\"", "an object".
std::string describe(const nlohmann::json& value);

/// The members of one JSON object, read by key; `finish` refuses keys nobody read (typos).
class ObjectReader {
 public:
  /// `value` must outlive the reader; `source` is copied. Throws DataError when `value` is not an object.
  ObjectReader(const nlohmann::json& value, std::string pointer, const std::string& source);
  [[nodiscard]] bool has(const std::string& key) const;
  /// The member; throws DataError naming the key when it is missing.
  const nlohmann::json& required(const std::string& key);
  /// The member, or nullptr when it is missing (or null).
  const nlohmann::json* optional(const std::string& key);
  /// Member `key` is given as null.
  [[nodiscard]] bool is_null(const std::string& key) const;
  /// The pointer of member `key`.
  [[nodiscard]] std::string pointer(const std::string& key) const;
  [[nodiscard]] const std::string& pointer() const { return pointer_; }
  [[nodiscard]] const std::string& source() const { return source_; }
  /// Throws DataError naming the first member that was never read.
  void finish() const;

  std::string string(const std::string& key);
  std::string string_or(const std::string& key, const std::string& fallback);
  double number(const std::string& key, double minimum, double maximum);
  double number_or(const std::string& key, double fallback, double minimum, double maximum);
  std::int64_t integer(const std::string& key, std::int64_t minimum, std::int64_t maximum);
  std::int64_t integer_or(const std::string& key, std::int64_t fallback, std::int64_t minimum,
                          std::int64_t maximum);
  std::uint64_t unsigned_or(const std::string& key, std::uint64_t fallback);
  bool boolean_or(const std::string& key, bool fallback);

 private:
  const nlohmann::json& value_;
  std::string pointer_;
  std::string source_;  // a copy: a caller may pass a temporary
  std::set<std::string> read_;
};

/// One value of a document read by its consumers (trial records): lenient about a missing or null member
/// (the fallback) and strict about its type, so that no damaged record reaches nlohmann's own type errors.
/// Every error is a DataError naming the source and the member's JSON pointer.
class JsonView {
 public:
  JsonView(const nlohmann::json& value, std::string pointer, std::string source)
      : value_(value), pointer_(std::move(pointer)), source_(std::move(source)) {}
  [[nodiscard]] const nlohmann::json& json() const { return value_; }
  [[nodiscard]] const std::string& pointer() const { return pointer_; }
  [[nodiscard]] const std::string& source() const { return source_; }
  /// True when the member is present and not null (false for a value that is not an object).
  [[nodiscard]] bool has(const std::string& key) const;
  /// The member as an object; an empty object when missing or null; throws DataError for another type.
  [[nodiscard]] JsonView object(const std::string& key) const;
  /// The member as an array; an empty array when missing or null; throws DataError for another type.
  [[nodiscard]] JsonView array(const std::string& key) const;
  /// The elements of this array (0 for a value that is not an array).
  [[nodiscard]] std::size_t size() const;
  /// Element `index` of this array, which must be an object; throws DataError otherwise.
  [[nodiscard]] JsonView object_at(std::size_t index) const;
  /// Element `index` of this array, as it is.
  [[nodiscard]] JsonView at(std::size_t index) const;
  [[nodiscard]] std::string string_or(const std::string& key, const std::string& fallback) const;
  [[nodiscard]] bool boolean_or(const std::string& key, bool fallback) const;
  /// The member as a number in [minimum, maximum], or nullopt when missing or null.
  [[nodiscard]] std::optional<double> optional_number(const std::string& key, double minimum,
                                                      double maximum) const;
  [[nodiscard]] double number_or(const std::string& key, double fallback, double minimum,
                                 double maximum) const;
  /// The member as a number in [minimum, maximum]; throws DataError when it is missing.
  [[nodiscard]] double number(const std::string& key, double minimum, double maximum) const;
  [[nodiscard]] std::int64_t integer_or(const std::string& key, std::int64_t fallback, std::int64_t minimum,
                                        std::int64_t maximum) const;

 private:
  [[nodiscard]] const nlohmann::json* member(const std::string& key) const;
  const nlohmann::json& value_;
  std::string pointer_;
  std::string source_;  // a copy: a view may outlive the string it was made from
};

/// The value as a string / number in range / integer in range; throws DataError naming `pointer`.
/// The longest string any field of a study file may hold: 64 KiB.
inline constexpr std::size_t kMaxStringBytes = std::size_t{64} << 10;

std::string as_string(const nlohmann::json& value, const std::string& pointer, const std::string& source);
double as_number(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                 double minimum, double maximum);
std::int64_t as_integer(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                        std::int64_t minimum, std::int64_t maximum);
/// The value as an unsigned 64-bit integer: digits, or exponent form when it is an exact integer below 2^53
/// (1e3); throws DataError naming `pointer` for anything else (a fraction, a negative, text, null).
std::uint64_t as_unsigned(const nlohmann::json& value, const std::string& pointer, const std::string& source);
/// `pointer` + "/" + `key` with RFC 6901 escapes.
std::string child_pointer(const std::string& pointer, const std::string& key);
std::string child_pointer(const std::string& pointer, std::size_t index);

}  // namespace calligraphy::json_detail
