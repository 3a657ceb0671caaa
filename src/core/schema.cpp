// The generic half of the schema (schema.hpp): range checks, the command line's text, docs tables. JSON
// reading and writing and the JSON Schema are in schema_json.cpp.
#include "calligraphy/core/schema.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <regex>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "core/utc_time.hpp"

namespace calligraphy {
namespace {

std::string quoted(std::string_view text) {
  std::string out(1, '\'');
  out.append(text);
  out.push_back('\'');
  return out;
}

std::string integer_range_text(const SchemaField& field) {
  if (field.integer_unsigned) return "0..18446744073709551615";
  return std::to_string(field.integer_low) + ".." + std::to_string(field.integer_high);
}

}  // namespace

std::string whole_option_range_text(const SchemaField& field) {
  const double low = field.range.low * field.option_factor;
  const double high = field.range.high * field.option_factor;
  const auto first = static_cast<std::int64_t>(field.range.low_open ? std::floor(low) + 1.0 : std::ceil(low));
  const auto last =
      static_cast<std::int64_t>(field.range.high_open ? std::ceil(high) - 1.0 : std::floor(high));
  return std::to_string(first) + ".." + std::to_string(last);
}

namespace {

// A whole number as the command line writes it: digits, '-' first only for a negative value; no '+', no
// spaces, no "-0" (which would say a sign the value does not have).
template <typename T>
std::optional<T> parse_whole(std::string_view text) {
  if (text.empty() || text.starts_with("-0")) return std::nullopt;
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace

std::string join_spellings(std::span<const std::string_view> spellings, std::string_view separator,
                           std::string_view quote) {
  std::string out;
  for (const std::string_view spelling : spellings) {
    if (!out.empty()) out += separator;
    out += std::string(quote) + std::string(spelling) + std::string(quote);
  }
  return out;
}

void throw_not_a_spelling(std::string_view text, std::span<const std::string_view> spellings) {
  throw InvalidArgument(quoted(text) + " is not one of " + join_spellings(spellings, ", ", "'"));
}

std::string_view to_string(FieldKind kind) noexcept {
  switch (kind) {
    case FieldKind::number:
      return "number";
    case FieldKind::integer:
      return "integer";
    case FieldKind::boolean:
      return "boolean";
    case FieldKind::enumeration:
      return "enumeration";
    case FieldKind::string:
      return "string";
    case FieldKind::object:
      return "object";
    case FieldKind::object_list:
      return "object list";
    case FieldKind::variant:
      return "variant";
    case FieldKind::number_array:
      return "number array";
  }
  return "?";
}

std::string SchemaField::range_text() const {
  switch (kind) {
    case FieldKind::number:
    case FieldKind::number_array:
      return range.text(unit);
    case FieldKind::integer:
      return integer_range_text(*this);
    case FieldKind::boolean:
      return "true|false";
    case FieldKind::enumeration:
    case FieldKind::variant:
      return join_spellings(spellings(), "|");
    default:
      return "";
  }
}

std::int64_t SchemaField::integer_value(const void* object) const {
  return get_integer != nullptr ? get_integer(object) : std::llround(get_number(*this, object, 0));
}

void SchemaField::set_integer_value(void* object, std::int64_t value) const {
  if (set_integer != nullptr) {
    set_integer(object, value);
  } else {
    set_number(*this, object, 0, static_cast<double>(value));
  }
}

bool SchemaField::holds_valid_value(const void* object) const {
  switch (kind) {
    case FieldKind::number:
      return range.contains(get_number(*this, object, 0));
    case FieldKind::number_array:
      for (std::size_t i = 0; i < array_size; ++i) {
        if (!range.contains(get_number(*this, object, i))) return false;
      }
      return true;
    case FieldKind::integer: {
      if (integer_unsigned) return true;
      const std::int64_t value = integer_value(object);
      return value >= integer_low && value <= integer_high;
    }
    case FieldKind::string: {
      const std::string& text = get_string(object);
      try {
        check_string(text);
      } catch (const InvalidArgument&) {
        return false;
      }
      // Code points, as JSON Schema's minLength counts them: every byte but a UTF-8 continuation byte.
      const auto characters = static_cast<std::size_t>(std::count_if(
          text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
      if (characters < min_length) return false;
      return pattern.empty() ||
             std::regex_search(text, std::regex(pattern.begin(), pattern.end(), std::regex::ECMAScript));
    }
    case FieldKind::object_list: {
      const std::size_t size = list_size(object);
      return size >= min_items && size <= max_items;
    }
    case FieldKind::boolean:
    case FieldKind::enumeration:
    case FieldKind::object:
    case FieldKind::variant:
      return true;
  }
  return true;
}

std::string SchemaField::description() const {
  std::string out(doc);
  if (!unit.empty()) out += " [" + std::string(unit) + "]";
  const std::string range_words = range_text();
  if (!range_words.empty() && kind != FieldKind::enumeration && kind != FieldKind::boolean)
    out += ", " + range_words;
  return out;
}

const SchemaField* Schema::field(std::string_view wanted) const noexcept {
  for (const SchemaField& f : fields) {
    if (f.name == wanted || (!f.option.empty() && f.option == wanted)) return &f;
  }
  return nullptr;
}

void check_field(const Schema& schema, const SchemaField& field, const void* object) {
  const std::string qualified = std::string(schema.name) + "." + std::string(field.name);
  switch (field.kind) {
    case FieldKind::number:
      check_parameter(qualified, field.get_number(field, object, 0), field.unit, field.range);
      break;
    case FieldKind::number_array:
      for (std::size_t i = 0; i < field.array_size; ++i) {
        check_parameter(qualified + "[" + std::to_string(i) + "]", field.get_number(field, object, i),
                        field.unit, field.range);
      }
      break;
    case FieldKind::integer:
      if (!field.integer_unsigned) {
        const std::int64_t value = field.integer_value(object);
        if (value < field.integer_low || value > field.integer_high) {
          throw InvalidArgument(qualified + " = " + std::to_string(value) + " must be in " +
                                integer_range_text(field));
        }
      }
      break;
    case FieldKind::object:
      if (const void* nested = field.get_object(object)) check_schema(*field.nested(), nested);
      break;
    case FieldKind::variant:
      check_schema(*field.variant_schema(field.variant_index(object)), field.variant_get(object));
      break;
    case FieldKind::object_list:
      for (std::size_t i = 0; i < field.list_size(object); ++i)
        check_schema(*field.nested(), field.list_at(object, i));
      break;
    case FieldKind::boolean:
    case FieldKind::enumeration:
    case FieldKind::string:
      break;
  }
}

void check_schema(const Schema& schema, const void* object) {
  for (const SchemaField& field : schema.fields) check_field(schema, field, object);
  if (schema.check_rules != nullptr) schema.check_rules(object);
}

void SchemaField::check_string(std::string_view text) const {
  if (string_format == StringFormat::utc_time) (void)utc_seconds(text);
  if (string_format == StringFormat::sha256 && !text.empty() && !is_sha256_hex(text))
    throw InvalidArgument("expected 64 lower-case hex digits (a SHA-256) or \"\"");
}

void set_field_from_text(const SchemaField& field, void* object, std::string_view text) {
  switch (field.kind) {
    case FieldKind::number: {
      if (field.option_whole) {
        const std::optional<std::int64_t> whole = parse_whole<std::int64_t>(text);
        const double value = whole ? static_cast<double>(*whole) / field.option_factor : 0.0;
        if (!whole || !field.range.contains(value))
          throw InvalidArgument(quoted(text) + " is not a whole number of " + std::string(field.option_unit) +
                                " in " + whole_option_range_text(field));
        field.set_number(field, object, 0, value);
        return;
      }
      const std::optional<double> value = parse_finite_double(text);
      // '+400', ' 400' and '0x190' are numbers to some readers: say which spelling is read.
      if (!value)
        throw InvalidArgument(quoted(text) + " is not a finite decimal number (such as 400, -0.5 or 1e-3)");
      field.set_number(field, object, 0, *value / field.option_factor);
      return;
    }
    case FieldKind::integer: {
      if (field.integer_unsigned) {
        const std::optional<std::uint64_t> value = parse_whole<std::uint64_t>(text);
        if (!value)
          throw InvalidArgument(quoted(text) + " is not an integer in " + integer_range_text(field));
        field.set_unsigned(object, *value);
        return;
      }
      const std::optional<std::int64_t> value = parse_whole<std::int64_t>(text);
      if (!value || *value < field.integer_low || *value > field.integer_high)
        throw InvalidArgument(quoted(text) + " is not an integer in " + integer_range_text(field));
      field.set_integer_value(object, *value);
      return;
    }
    case FieldKind::boolean:
      // The command line's words only, as every on|off option takes them (`train --guidance true` is
      // refused too); JSON's true and false are the record's form, not text.
      if (text == "on") {
        field.set_boolean(object, true);
      } else if (text == "off") {
        field.set_boolean(object, false);
      } else {
        throw InvalidArgument(quoted(text) + " is not one of 'on', 'off'");
      }
      return;
    case FieldKind::enumeration: {
      const auto spellings = field.spellings();
      for (std::size_t i = 0; i < spellings.size(); ++i) {
        if (spellings[i] == text) {
          field.set_choice(object, i);
          return;
        }
      }
      throw_not_a_spelling(text, spellings);
    }
    case FieldKind::string:
      field.check_string(text);
      field.set_string(object, std::string(text));
      return;
    default:
      throw InvalidArgument(std::string(field.name) + ": a " + std::string(to_string(field.kind)) +
                            " has no text form");
  }
}

std::string field_text(const SchemaField& field, const void* object) {
  switch (field.kind) {
    case FieldKind::number:
      if (field.option_whole)  // 0.007 s x 1000 is 7.000000000000001: the whole number it stands for
        return std::to_string(std::llround(field.get_number(field, object, 0) * field.option_factor));
      return shortest_decimal(field.get_number(field, object, 0) * field.option_factor);
    case FieldKind::integer:
      return field.integer_unsigned ? std::to_string(field.get_unsigned(object))
                                    : std::to_string(field.integer_value(object));
    case FieldKind::boolean:
      return field.get_boolean(object) ? "on" : "off";
    case FieldKind::enumeration:
      return std::string(field.spellings()[field.get_choice(object)]);
    case FieldKind::string:
      return field.get_string(object);
    default:
      throw InvalidArgument(std::string(field.name) + ": a " + std::string(to_string(field.kind)) +
                            " has no text form");
  }
}

std::string schema_markdown(const Schema& schema) {
  std::string out =
      "| field | kind | unit | range | default | meaning |\n| --- | --- | --- | --- | --- | --- |\n";
  const void* defaults = schema.defaults();
  for (const SchemaField& field : schema.fields) {
    std::string default_text;
    switch (field.kind) {
      case FieldKind::number:
        default_text = shortest_decimal(field.get_number(field, defaults, 0));
        break;
      case FieldKind::boolean:  // as JSON writes it, not as the command line does ("on")
        default_text = field.get_boolean(defaults) ? "true" : "false";
        break;
      case FieldKind::integer:
      case FieldKind::enumeration:
        default_text = field_text(field, defaults);
        break;
      case FieldKind::string:
        default_text = "\"" + field.get_string(defaults) + "\"";
        break;
      case FieldKind::object:
        default_text = field.get_object(defaults) ? std::string(field.nested()->name) : "null";
        break;
      case FieldKind::variant:
        default_text = std::string(field.spellings()[field.variant_index(defaults)]);
        break;
      case FieldKind::object_list:
        default_text = "[]";
        break;
      case FieldKind::number_array:
        for (std::size_t i = 0; i < field.array_size; ++i)
          default_text += (i ? ", " : "[") + shortest_decimal(field.get_number(field, defaults, i));
        default_text += "]";
        break;
    }
    std::string range = field.range_text();
    for (std::size_t at = range.find('|'); at != std::string::npos; at = range.find('|', at + 2))
      range.replace(at, 1, "\\|");  // a bar inside a Markdown table cell
    // A default that is no value of the field (an empty id, a list that must hold one) is none.
    const std::string default_cell = field.holds_valid_value(defaults) ? "`" + default_text + "`" : "-";
    out += "| `" + std::string(field.name) + "` | " + std::string(to_string(field.kind)) + " | " +
           std::string(field.unit) + " | " + range + " | " + default_cell + " | " + std::string(field.doc) +
           " |\n";
  }
  return out;
}

}  // namespace calligraphy
