#include "core/json_reader.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "core/json_document.hpp"

namespace calligraphy::json_detail {

void fail(const std::string& source, const std::string& pointer, const std::string& message) {
  throw DataError(source + ": " + (pointer.empty() ? "/" : pointer) + ": " + message);
}

nlohmann::json parse_json(std::string_view text, const std::string& source) {
  return parse_json_document(text, source);
}

std::string describe(const nlohmann::json& value) {
  if (value.is_object()) return "an object";
  if (value.is_array()) return "an array";
  std::string text = value.dump();
  if (text.size() > 40) {
    text.resize(37);
    text.append("...");
  }
  return text;
}

std::string child_pointer(const std::string& pointer, const std::string& key) {
  std::string escaped;
  for (const char c : key) {
    if (c == '~') {
      escaped += "~0";
    } else if (c == '/') {
      escaped += "~1";
    } else {
      escaped += c;
    }
  }
  return pointer + "/" + escaped;
}

std::string child_pointer(const std::string& pointer, std::size_t index) {
  return pointer + "/" + std::to_string(index);
}

std::string as_string(const nlohmann::json& value, const std::string& pointer, const std::string& source) {
  if (!value.is_string()) fail(source, pointer, "expected a string, got " + describe(value));
  // No field of a study's files is longer (a path, a row of characters, a note): a longer one is damage, and
  // would otherwise be copied into every row of the tables and every page.
  if (value.get_ref<const std::string&>().size() > kMaxStringBytes) {
    fail(source, pointer,
         "expected a string of at most " + std::to_string(kMaxStringBytes) + " bytes, got one of " +
             std::to_string(value.get_ref<const std::string&>().size()) + " bytes");
  }
  return value.get<std::string>();
}

double as_number(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                 double minimum, double maximum) {
  if (!value.is_number()) fail(source, pointer, "expected a number, got " + describe(value));
  const double number = value.get<double>();
  if (!std::isfinite(number) || number < minimum || number > maximum) {
    fail(source, pointer,
         "expected a number in [" + nlohmann::json(minimum).dump() + ", " + nlohmann::json(maximum).dump() +
             "], got " + describe(value));
  }
  return number;
}

namespace {

// Every integer up to 2^53 is exact as a double; a number written with a fraction or an exponent above that
// may already have been rounded when it was read, so it is not taken for the integer it seems to be.
constexpr double kLargestExactInteger = 9007199254740992.0;

// "expected an integer in minimum..maximum, got VALUE" (the range as the schema's tables and the options
// write it), saying why when the value is in the range but not an integer the file states exactly (a fraction
// or an exponent beyond 2^53: 1e19).
[[noreturn]] void fail_integer(const nlohmann::json& value, const std::string& pointer,
                               const std::string& source, const std::string& range) {
  std::string message = "expected an integer in " + range + ", got " + describe(value);
  const bool whole_float = value.is_number_float() && std::isfinite(value.get<double>()) &&
                           std::floor(value.get<double>()) == value.get<double>();
  // Digits alone read as an integer up to 2^64; a whole float below that was written with an exponent or a
  // fraction, one from 2^64 on may be digits alone, past every 64-bit integer.
  if (whole_float && std::fabs(value.get<double>()) >= 18446744073709551616.0) {
    message += " (beyond every 64-bit integer)";
  } else if (whole_float && std::fabs(value.get<double>()) >= kLargestExactInteger) {
    message +=
        " (written with an exponent or a fraction: above 2^53 = 9007199254740992 write it in digits, "
        "as such a number may have been rounded)";
  }
  fail(source, pointer, message);
}

bool is_exact_integral_float(const nlohmann::json& value) {
  if (!value.is_number_float()) return false;
  const double number = value.get<double>();
  return std::isfinite(number) && std::floor(number) == number && std::fabs(number) < kLargestExactInteger;
}

}  // namespace

std::int64_t as_integer(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                        std::int64_t minimum, std::int64_t maximum) {
  const std::string range = std::to_string(minimum) + ".." + std::to_string(maximum);
  if (!value.is_number_integer() && !is_exact_integral_float(value))
    fail_integer(value, pointer, source, range);
  if (value.is_number_unsigned() &&
      value.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    fail_integer(value, pointer, source, range);
  }
  const std::int64_t number =
      value.is_number_float() ? static_cast<std::int64_t>(value.get<double>()) : value.get<std::int64_t>();
  if (number < minimum || number > maximum) fail_integer(value, pointer, source, range);
  return number;
}

std::uint64_t as_unsigned(const nlohmann::json& value, const std::string& pointer,
                          const std::string& source) {
  static const std::string kRange = "0..18446744073709551615";
  if (value.is_number_unsigned()) return value.get<std::uint64_t>();
  if (value.is_number_integer() && value.get<std::int64_t>() >= 0) return value.get<std::uint64_t>();
  if (is_exact_integral_float(value) && value.get<double>() >= 0.0)
    return static_cast<std::uint64_t>(value.get<double>());
  fail_integer(value, pointer, source, kRange);
}

ObjectReader::ObjectReader(const nlohmann::json& value, std::string pointer, const std::string& source)
    : value_(value), pointer_(std::move(pointer)), source_(source) {
  if (!value_.is_object()) fail(source_, pointer_, "expected an object, got " + describe(value_));
}

bool ObjectReader::has(const std::string& key) const { return value_.contains(key); }

std::string ObjectReader::pointer(const std::string& key) const { return child_pointer(pointer_, key); }

const nlohmann::json& ObjectReader::required(const std::string& key) {
  const auto found = value_.find(key);
  if (found == value_.end()) fail(source_, pointer(key), "missing (required)");
  read_.insert(key);
  return *found;
}

const nlohmann::json* ObjectReader::optional(const std::string& key) {
  const auto found = value_.find(key);
  if (found == value_.end()) return nullptr;
  read_.insert(key);
  return found->is_null() ? nullptr : &*found;
}

bool ObjectReader::is_null(const std::string& key) const {
  const auto found = value_.find(key);
  return found != value_.end() && found->is_null();
}

void ObjectReader::finish() const {
  for (const auto& item : value_.items()) {
    if (read_.count(item.key()) == 0) fail(source_, pointer(item.key()), "unknown key");
  }
}

std::string ObjectReader::string(const std::string& key) {
  return as_string(required(key), pointer(key), source_);
}

std::string ObjectReader::string_or(const std::string& key, const std::string& fallback) {
  const nlohmann::json* value = optional(key);
  return value ? as_string(*value, pointer(key), source_) : fallback;
}

double ObjectReader::number(const std::string& key, double minimum, double maximum) {
  return as_number(required(key), pointer(key), source_, minimum, maximum);
}

double ObjectReader::number_or(const std::string& key, double fallback, double minimum, double maximum) {
  const nlohmann::json* value = optional(key);
  return value ? as_number(*value, pointer(key), source_, minimum, maximum) : fallback;
}

std::int64_t ObjectReader::integer(const std::string& key, std::int64_t minimum, std::int64_t maximum) {
  return as_integer(required(key), pointer(key), source_, minimum, maximum);
}

std::int64_t ObjectReader::integer_or(const std::string& key, std::int64_t fallback, std::int64_t minimum,
                                      std::int64_t maximum) {
  const nlohmann::json* value = optional(key);
  return value ? as_integer(*value, pointer(key), source_, minimum, maximum) : fallback;
}

std::uint64_t ObjectReader::unsigned_or(const std::string& key, std::uint64_t fallback) {
  const nlohmann::json* value = optional(key);
  return value ? as_unsigned(*value, pointer(key), source_) : fallback;
}

bool ObjectReader::boolean_or(const std::string& key, bool fallback) {
  const nlohmann::json* value = optional(key);
  if (!value) return fallback;
  if (!value->is_boolean()) fail(source_, pointer(key), "expected true or false, got " + describe(*value));
  return value->get<bool>();
}

namespace {
const nlohmann::json& empty_object() {
  static const nlohmann::json empty = nlohmann::json::object();
  return empty;
}
const nlohmann::json& empty_array() {
  static const nlohmann::json empty = nlohmann::json::array();
  return empty;
}
}  // namespace

const nlohmann::json* JsonView::member(const std::string& key) const {
  if (!value_.is_object()) fail(source_, pointer_, "expected an object, got " + describe(value_));
  const auto found = value_.find(key);
  return found == value_.end() || found->is_null() ? nullptr : &*found;
}

bool JsonView::has(const std::string& key) const {
  if (!value_.is_object()) return false;
  const auto found = value_.find(key);
  return found != value_.end() && !found->is_null();
}

JsonView JsonView::object(const std::string& key) const {
  const nlohmann::json* value = member(key);
  if (value && !value->is_object()) {
    fail(source_, child_pointer(pointer_, key), "expected an object, got " + describe(*value));
  }
  return {value ? *value : empty_object(), child_pointer(pointer_, key), source_};
}

JsonView JsonView::array(const std::string& key) const {
  const nlohmann::json* value = member(key);
  if (value && !value->is_array()) {
    fail(source_, child_pointer(pointer_, key), "expected an array, got " + describe(*value));
  }
  return {value ? *value : empty_array(), child_pointer(pointer_, key), source_};
}

std::size_t JsonView::size() const { return value_.is_array() ? value_.size() : 0; }

JsonView JsonView::at(std::size_t index) const {
  if (!value_.is_array() || index >= value_.size()) {
    fail(source_, child_pointer(pointer_, index), "missing (required)");
  }
  return {value_[index], child_pointer(pointer_, index), source_};
}

JsonView JsonView::object_at(std::size_t index) const {
  JsonView element = at(index);
  if (!element.json().is_object()) {
    fail(source_, element.pointer(), "expected an object, got " + describe(element.json()));
  }
  return element;
}

std::string JsonView::string_or(const std::string& key, const std::string& fallback) const {
  const nlohmann::json* value = member(key);
  return value ? as_string(*value, child_pointer(pointer_, key), source_) : fallback;
}

bool JsonView::boolean_or(const std::string& key, bool fallback) const {
  const nlohmann::json* value = member(key);
  if (!value) return fallback;
  if (!value->is_boolean()) {
    fail(source_, child_pointer(pointer_, key), "expected true or false, got " + describe(*value));
  }
  return value->get<bool>();
}

std::optional<double> JsonView::optional_number(const std::string& key, double minimum,
                                                double maximum) const {
  const nlohmann::json* value = member(key);
  if (!value) return std::nullopt;
  return as_number(*value, child_pointer(pointer_, key), source_, minimum, maximum);
}

double JsonView::number_or(const std::string& key, double fallback, double minimum, double maximum) const {
  return optional_number(key, minimum, maximum).value_or(fallback);
}

double JsonView::number(const std::string& key, double minimum, double maximum) const {
  const std::optional<double> value = optional_number(key, minimum, maximum);
  if (!value) fail(source_, child_pointer(pointer_, key), "missing (required)");
  return *value;
}

std::int64_t JsonView::integer_or(const std::string& key, std::int64_t fallback, std::int64_t minimum,
                                  std::int64_t maximum) const {
  const nlohmann::json* value = member(key);
  return value ? as_integer(*value, child_pointer(pointer_, key), source_, minimum, maximum) : fallback;
}

}  // namespace calligraphy::json_detail
