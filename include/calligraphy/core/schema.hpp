#pragma once
/// \file schema.hpp
/// One description of every struct that shapes a trial: its fields with their JSON key, kind (number,
/// integer, boolean, enumeration, string, nested object, list of objects, fixed-length number array), unit,
/// range, default (the struct's own member initialiser), documentation and, where the command line takes it,
/// its option. From it and from nothing else come the range checks (`check_schema`), the JSON form
/// (`schema_json`, `schema_from_json`: strict, every error naming the source and the JSON pointer), the
/// command line's options (the CLI's `add_schema_options`), the JSON Schema 2020-12 that
/// `calligraphy schema` prints (`json_schema_text`) and the parameter tables of the documentation
/// (`schema_markdown`). Enumerations have one table each (`EnumTable`): value, the one spelling, doc.
///
/// A description is type-erased (function pointers made from member pointers), so that the generic code
/// lives once in `core` and holds no per-struct code; a struct's schema is built once, next to the struct,
/// with the field makers below (`number_field<&S::member>(...)`).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"

namespace calligraphy {

// ---------------------------------------------------------------------------------------------------------
// Enumerations

/// One value of an enumeration: the value, its one spelling (in every file, option and Python argument) and
/// one line of documentation.
template <typename E>
struct EnumEntry {
  E value;
  std::string_view spelling;
  std::string_view doc;
};

/// The table of enumeration `E`, specialised next to it: `name` ("GuidanceMode") and `entries` (a
/// std::array of EnumEntry<E>, in declaration order).
template <typename E>
struct EnumTable;

/// `value`'s one spelling; "?" for a value outside the table (a programming error, never thrown).
template <typename E>
[[nodiscard]] constexpr std::string_view enum_spelling(E value) noexcept {
  for (const EnumEntry<E>& entry : EnumTable<E>::entries) {
    if (entry.value == value) return entry.spelling;
  }
  return "?";
}

/// The value spelled `text`; nullopt for any other text (spellings are exact: no case folding).
template <typename E>
[[nodiscard]] constexpr std::optional<E> enum_from_spelling(std::string_view text) noexcept {
  for (const EnumEntry<E>& entry : EnumTable<E>::entries) {
    if (entry.spelling == text) return entry.value;
  }
  return std::nullopt;
}

/// Every spelling joined by `separator`: "fixed|fading|replay" for help texts, "'a', 'b'" for errors.
std::string join_spellings(std::span<const std::string_view> spellings, std::string_view separator,
                           std::string_view quote = "");

namespace schema_detail {
template <typename E>
inline constexpr auto spellings_of = [] {
  std::array<std::string_view, EnumTable<E>::entries.size()> out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = EnumTable<E>::entries[i].spelling;
  return out;
}();
}  // namespace schema_detail

/// Every spelling of `E`, in table order.
template <typename E>
[[nodiscard]] constexpr std::span<const std::string_view> enum_spellings() noexcept {
  return schema_detail::spellings_of<E>;
}

/// The value spelled `text`; throws InvalidArgument "'text' is not one of 'a', 'b', ..." otherwise.
template <typename E>
[[nodiscard]] E parse_enum(std::string_view text);

// ---------------------------------------------------------------------------------------------------------
// Fields and structs

/// What a field holds, and so its JSON type.
enum class FieldKind : std::uint8_t {
  number,        ///< double, finite, in `SchemaField::range` (JSON number)
  integer,       ///< a whole number in [SchemaField::integer_low, SchemaField::integer_high] (JSON integer)
  boolean,       ///< JSON true or false
  enumeration,   ///< one of the enumeration's spellings (JSON string)
  string,        ///< UTF-8 text (JSON string)
  object,        ///< a nested struct with a schema of its own (JSON object)
  object_list,   ///< a list of such structs (JSON array of objects)
  number_array,  ///< a fixed number of doubles, each in `SchemaField::range` (JSON array: a Vec2, a Vec3)
  variant,       ///< one of several structs, named by an enumeration in member `variant_tag` (a std::variant)
};

/// What a string field's text must be, beyond UTF-8.
enum class StringFormat : std::uint8_t {
  any,       ///< any text
  utc_time,  ///< a time of the calendar in UTC, "2024-05-01T12:34:56.789Z" (ISO 8601, the fraction optional)
  sha256,    ///< a SHA-256 as 64 lower-case hex digits (FIPS 180-4), or empty: none
  constant,  ///< the field's default and nothing else: a format's name, which a reader checks first
};

/// The JSON name of a kind: "number", "integer", "boolean", "enumeration", "string", "object", ...
[[nodiscard]] std::string_view to_string(FieldKind kind) noexcept;

struct Schema;

/// One field of a struct, type-erased: the accessors take the struct as `void*`, made type-safe by the field
/// makers below. Every member but the accessors is data for the generic code.
struct SchemaField {
  std::string_view name = {};  ///< the JSON key and Python name, units in it ("rate_hz")
  FieldKind kind = FieldKind::number;
  std::string_view unit = {};    ///< SI: "m", "s", "N", "N/m", "N s/m", "Hz", "kg"; empty when dimensionless
  std::string_view doc = {};     ///< one line: what the value is, without unit or range
  std::string_view source = {};  ///< where a formula or a number comes from (paper, standard); may be empty
  ParameterRange range = {};     ///< number, number_array: the values accepted
  std::int64_t integer_low = 0;  ///< integer: the least value
  /// integer: the greatest value; with `integer_unsigned` the range is [0, 2^64 - 1] and these are unused
  std::int64_t integer_high = std::numeric_limits<std::int64_t>::max();
  bool integer_unsigned = false;
  std::size_t array_size = 0;           ///< number_array: how many numbers
  const Schema* (*nested)() = nullptr;  ///< object, object_list: the nested struct's schema
  std::span<const std::string_view> (*spellings)() = nullptr;  ///< enumeration: spellings in table order
  std::string_view enum_name = {};  ///< enumeration, variant: the enumeration's name ("GuidanceMode")
  StringFormat string_format = StringFormat::any;  ///< string: what its text must be
  /// string: what its text must be beyond `string_format`, as the JSON Schema states it: at least
  /// `min_length` characters (code points, as JSON Schema counts them) and a match of `pattern` (ECMA-262,
  /// JSON Schema's dialect; not with a format that states a pattern of its own). The struct's reader checks
  /// them in words of its own; here they decide, with the rest, whether a default is a value of the field.
  std::string_view pattern = {};
  std::size_t min_length = 0;
  /// object_list: the fewest and the most elements (JSON Schema's minItems, maxItems), checked as `pattern`.
  std::size_t min_items = 0;
  std::size_t max_items = std::numeric_limits<std::size_t>::max();
  /// object: std::optional of the struct; JSON null when empty
  bool nullable = false;
  /// variant: the key naming the alternative ("mode"), spelled by the enumeration `spellings`, whose i-th
  /// value is the variant's i-th alternative
  std::string_view variant_tag = {};
  const Schema* (*variant_schema)(std::size_t index) = nullptr;
  /// The command line's option ("--rate"), empty when the command line does not take the field; its value's
  /// name in help ("HZ") and, when the option is given in another unit than the field (whole milliseconds
  /// for a field in seconds), that unit and the factor option value = field value x factor.
  std::string_view option = {};
  std::string_view option_value_name = {};
  std::string_view option_unit = {};
  double option_factor = 1.0;
  /// The option takes whole numbers of `option_unit` only ("--watchdog-ms 20", not "20.5" or "1e3"): the
  /// command line's integer syntax, for a field the documents hold as a real number in another unit.
  bool option_whole = false;
  /// A document of a version older than this may lack the field, which then takes its default (a field
  /// added since); 0: the field was always there.
  int since_version = 0;
  /// A document of any version may lack the field, which then takes its default: a key written only when it
  /// has a value (a link to what may not exist), or one added to a format without a new version.
  bool omissible = false;

  // Accessors; each non-null only for its kinds. An enumeration is read and set by its table index.
  /// number, number_array: element `index` (0 for a number). Given the field itself, so that a field made
  /// from a ParameterTable entry finds its member by `table_slot`.
  double (*get_number)(const SchemaField& self, const void* object, std::size_t index) = nullptr;
  void (*set_number)(const SchemaField& self, void* object, std::size_t index, double value) = nullptr;
  std::size_t table_slot = 0;  ///< a field made by `table_fields`: its entry in the struct's ParameterTable
  std::int64_t (*get_integer)(const void* object) = nullptr;  ///< signed kinds
  std::uint64_t (*get_unsigned)(const void* object) = nullptr;
  void (*set_integer)(void* object, std::int64_t value) = nullptr;
  void (*set_unsigned)(void* object, std::uint64_t value) = nullptr;
  bool (*get_boolean)(const void* object) = nullptr;
  void (*set_boolean)(void* object, bool value) = nullptr;
  std::size_t (*get_choice)(const void* object) = nullptr;
  void (*set_choice)(void* object, std::size_t index) = nullptr;
  const std::string& (*get_string)(const void* object) = nullptr;
  void (*set_string)(void* object, std::string value) = nullptr;
  const void* (*get_object)(const void* object) = nullptr;
  void* (*mutable_object)(void* object) = nullptr;
  bool (*has_object)(const void* object) = nullptr;  ///< nullable: the optional holds a value
  void* (*emplace_object)(void* object) = nullptr;   ///< nullable: a default value, emplaced
  void (*reset_object)(void* object) = nullptr;      ///< nullable: empty
  std::size_t (*variant_index)(const void* object) = nullptr;
  const void* (*variant_get)(const void* object) = nullptr;             ///< the alternative held
  void* (*variant_emplace)(void* object, std::size_t index) = nullptr;  ///< alternative `index`, default
  std::size_t (*list_size)(const void* object) = nullptr;
  const void* (*list_at)(const void* object, std::size_t index) = nullptr;
  void* (*list_append)(void* object) = nullptr;  ///< a default element at the end
  void (*list_clear)(void* object) = nullptr;

  /// integer, signed: the value, through `get_integer`, or through `get_number` for a count a ParameterTable
  /// keeps as a double (make_whole_number_kind).
  [[nodiscard]] std::int64_t integer_value(const void* object) const;
  /// integer, signed: sets the value, through `set_integer` or `set_number` as `integer_value` reads it.
  void set_integer_value(void* object, std::int64_t value) const;

  /// string: throws InvalidArgument quoting `text` and saying what it must be when it is not of the field's
  /// `string_format` (a StringFormat::utc_time that is no time of the calendar in UTC).
  void check_string(std::string_view text) const;

  /// Whether the field's value in `object` is one the field takes: a number in its range, an integer within
  /// its bounds, text of its format, length and pattern, a list of its size (a nested struct or a variant:
  /// yes). A default that is not (an empty id, a plan that must hold a trial, a count whose 0 means "none")
  /// is no value a document could state: the JSON Schema and the docs' table state none.
  [[nodiscard]] bool holds_valid_value(const void* object) const;
  /// "doc [unit], range" for help and docs: "servo rate [Hz], in [100, 100000] Hz".
  [[nodiscard]] std::string description() const;
  /// The range as text ("in [0, 1]", "0..18446744073709551615", "fixed|fading"); empty for strings and
  /// nested kinds.
  [[nodiscard]] std::string range_text() const;
};

/// A struct's description: its name in errors ("TrialSpec"), one line of doc, its fields in order, its
/// default instance (the member initialisers) and its cross-field rules.
struct Schema {
  std::string_view name;
  std::string_view doc;
  std::span<const SchemaField> fields;
  const void* (*defaults)() = nullptr;
  /// The struct's rules between fields, after every field is in range (may be null); throws
  /// InvalidArgument naming the field.
  void (*check_rules)(const void* object) = nullptr;

  /// The field called `name` (its key or its option); nullptr when there is none.
  [[nodiscard]] const SchemaField* field(std::string_view name) const noexcept;
};

/// Specialise next to each struct: `static const Schema& get()`, built once.
template <typename S>
struct SchemaOf;

/// Checks one field of `object` against its range (a nested struct whole, its rules included); throws
/// InvalidArgument "Struct.field = value unit must be ...".
void check_field(const Schema& schema, const SchemaField& field, const void* object);
/// Checks every field of `object` (described by `schema`) against its range, nested structs included, then
/// the struct's rules; throws InvalidArgument "Struct.field = value unit must be ..." for the first at fault.
void check_schema(const Schema& schema, const void* object);
template <typename S>
void check_schema(const S& object) {
  check_schema(SchemaOf<S>::get(), &object);
}

/// Sets field `field` of `object` from its text as the command line spells it: a number (in the option's
/// unit when it has one), an integer (decimal digits, a leading '-' only where negatives are allowed; "-0"
/// is refused), "on"/"off" (as every on|off option), an enumeration's spelling, or text. Throws
/// InvalidArgument "'text' is not ..." naming the accepted values; the range check is `check_schema`'s (an
/// integer out of its range is refused here, as it has no other form).
void set_field_from_text(const SchemaField& field, void* object, std::string_view text);
/// The field's value as the command line spells it (numbers in shortest round-trip form, in the option's
/// unit). For scalar kinds only (InvalidArgument otherwise).
[[nodiscard]] std::string field_text(const SchemaField& field, const void* object);

/// How `schema_from_json` treats a missing member.
struct SchemaReadOptions {
  /// Every field is required (a record); false: a missing member keeps its default (a file a person wrote).
  /// An element of a list always states every field.
  bool require_all = false;
  /// With require_all: the document's version; a field whose `since_version` is newer, or an omissible
  /// field, may be missing and takes its default (listed in `SchemaReadResult::defaulted`).
  int version = std::numeric_limits<int>::max();
};

/// What a read filled in: the JSON pointers of fields that were missing and took their default.
struct SchemaReadResult {
  std::vector<std::string> defaulted;
};

/// `object` as a JSON object (2-space indent, keys in field order, numbers that read back to the same
/// doubles, enumerations spelled).
[[nodiscard]] std::string schema_json(const Schema& schema, const void* object);
template <typename S>
[[nodiscard]] std::string schema_json(const S& object) {
  return schema_json(SchemaOf<S>::get(), &object);
}

/// Reads the JSON object in `text` into `object` (which holds the defaults for what is missing): unknown
/// keys, null, a value of another type, an integer out of range and a number out of its field's range are
/// refused, then the struct's rules are checked. Throws DataError "SOURCE: /json/pointer: message" naming the
/// first value at fault (and malformed JSON by its byte offset).
SchemaReadResult schema_from_json(const Schema& schema, void* object, std::string_view text,
                                  const std::string& source, const SchemaReadOptions& options = {});
template <typename S>
[[nodiscard]] S schema_from_json(std::string_view text, const std::string& source,
                                 const SchemaReadOptions& options = {}) {
  S object{};
  schema_from_json(SchemaOf<S>::get(), &object, text, source, options);
  return object;
}

/// The JSON Schema (draft 2020-12) of a document whose root is `schema`'s struct: every field a property
/// with its type, `description` ("doc [unit]"), `default` (when the default is a value of the field:
/// SchemaField::holds_valid_value), ranges as minimum / maximum (exclusiveMinimum / exclusiveMaximum where
/// open), a text's minLength and pattern, a list's minItems and maxItems, enumerations as `enum`, nested
/// structs as `$defs` referenced by `$ref`,
/// `additionalProperties: false` and, with `all_required` (a record, read with
/// SchemaReadOptions::require_all), `required` listing every field but those added since the first version
/// and the omissible ones.
/// `id` and `title` name the document.
[[nodiscard]] std::string json_schema_text(const Schema& schema, std::string_view id, std::string_view title,
                                           bool all_required);

/// The fields as a Markdown table (field, kind, unit, range, default, doc), for the documentation; a default
/// that is no value of its field (SchemaField::holds_valid_value) is shown as `-`, none.
[[nodiscard]] std::string schema_markdown(const Schema& schema);

// ---------------------------------------------------------------------------------------------------------
// SchemaField makers: `number_field<&S::member>(name, unit, range, doc)` and so on; the struct type comes
// from the member pointer.

namespace schema_detail {
template <typename M>
struct member_of;
template <typename S, typename T>
struct member_of<T S::*> {
  using object = S;
  using type = T;
};
template <auto Member>
using object_t = typename member_of<decltype(Member)>::object;
template <auto Member>
using type_t = typename member_of<decltype(Member)>::type;

template <typename V, std::size_t... I>
const Schema* alternative_schema_at(std::size_t index, std::index_sequence<I...>) {
  const Schema* found = nullptr;
  ((found = (I == index ? &SchemaOf<std::variant_alternative_t<I, V>>::get() : found)), ...);
  return found;
}
template <typename V>
const Schema* alternative_schema(std::size_t index) {
  return alternative_schema_at<V>(index, std::make_index_sequence<std::variant_size_v<V>>{});
}
template <typename V, std::size_t... I>
V default_alternative_at(std::size_t index, std::index_sequence<I...>) {
  V out;
  ((I == index ? (void)(out = std::variant_alternative_t<I, V>{}) : (void)0), ...);
  return out;
}
template <typename V>
V default_alternative(std::size_t index) {
  return default_alternative_at<V>(index, std::make_index_sequence<std::variant_size_v<V>>{});
}

template <auto Member>
constexpr auto& ref(void* object) {
  return static_cast<object_t<Member>*>(object)->*Member;
}
template <auto Member>
constexpr const auto& cref(const void* object) {
  return static_cast<const object_t<Member>*>(object)->*Member;
}
}  // namespace schema_detail

/// What a field maker takes besides the member: documentation and the command line.
struct FieldText {
  std::string_view unit = {};
  std::string_view doc = {};
  std::string_view option = {};
  std::string_view option_value_name = {};
  std::string_view source = {};
  StringFormat format = StringFormat::any;  ///< a string field's
};

template <auto Member>
[[nodiscard]] constexpr SchemaField number_field(std::string_view name, ParameterRange range,
                                                 FieldText text) {
  SchemaField f{
      .name = name, .kind = FieldKind::number, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.range = range;
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.get_number = [](const SchemaField&, const void* o, std::size_t) -> double {
    return schema_detail::cref<Member>(o);
  };
  f.set_number = [](const SchemaField&, void* o, std::size_t, double v) {
    schema_detail::ref<Member>(o) = v;
  };
  return f;
}

/// A signed integer member (int, std::int64_t) in [low, high].
template <auto Member>
[[nodiscard]] constexpr SchemaField integer_field(std::string_view name, std::int64_t low, std::int64_t high,
                                                  FieldText text) {
  using T = schema_detail::type_t<Member>;
  SchemaField f{
      .name = name, .kind = FieldKind::integer, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.integer_low = low;
  f.integer_high = high;
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.get_integer = [](const void* o) -> std::int64_t { return schema_detail::cref<Member>(o); };
  f.set_integer = [](void* o, std::int64_t v) { schema_detail::ref<Member>(o) = static_cast<T>(v); };
  return f;
}

/// `field`, a number field of a double member that holds whole numbers only (a count a ParameterTable keeps
/// as a double, ParameterField::whole_number), made an integer field over the whole numbers of its range: its
/// JSON Schema then says "integer", as a count's does. Its number accessors stay and are read through
/// SchemaField::integer_value.
inline void make_whole_number_kind(SchemaField& field) {
  field.kind = FieldKind::integer;
  field.integer_low = static_cast<std::int64_t>(std::ceil(field.range.low));
  field.integer_high = static_cast<std::int64_t>(std::floor(field.range.high));
  field.range = {};
}

/// A std::uint64_t member taking every value (a seed).
template <auto Member>
[[nodiscard]] constexpr SchemaField unsigned_field(std::string_view name, FieldText text) {
  SchemaField f{
      .name = name, .kind = FieldKind::integer, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.integer_unsigned = true;
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.get_unsigned = [](const void* o) -> std::uint64_t { return schema_detail::cref<Member>(o); };
  f.set_unsigned = [](void* o, std::uint64_t v) { schema_detail::ref<Member>(o) = v; };
  return f;
}

template <auto Member>
[[nodiscard]] constexpr SchemaField boolean_field(std::string_view name, FieldText text) {
  SchemaField f{
      .name = name, .kind = FieldKind::boolean, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.option = text.option;
  f.option_value_name = text.option_value_name.empty() ? std::string_view("on|off") : text.option_value_name;
  f.get_boolean = [](const void* o) -> bool { return schema_detail::cref<Member>(o); };
  f.set_boolean = [](void* o, bool v) { schema_detail::ref<Member>(o) = v; };
  return f;
}

/// A member of an enumeration with an EnumTable.
template <auto Member>
[[nodiscard]] constexpr SchemaField enum_field(std::string_view name, FieldText text) {
  using E = schema_detail::type_t<Member>;
  SchemaField f{.name = name,
                .kind = FieldKind::enumeration,
                .unit = text.unit,
                .doc = text.doc,
                .source = text.source};
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.spellings = [] { return enum_spellings<E>(); };
  f.enum_name = EnumTable<E>::name;
  f.get_choice = [](const void* o) -> std::size_t {
    const E value = schema_detail::cref<Member>(o);
    for (std::size_t i = 0; i < EnumTable<E>::entries.size(); ++i) {
      if (EnumTable<E>::entries[i].value == value) return i;
    }
    return 0;
  };
  f.set_choice = [](void* o, std::size_t i) {
    schema_detail::ref<Member>(o) = EnumTable<E>::entries[i].value;
  };
  return f;
}

template <auto Member>
[[nodiscard]] constexpr SchemaField string_field(std::string_view name, FieldText text) {
  SchemaField f{
      .name = name, .kind = FieldKind::string, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.string_format = text.format;
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.get_string = [](const void* o) -> const std::string& { return schema_detail::cref<Member>(o); };
  f.set_string = [](void* o, std::string v) { schema_detail::ref<Member>(o) = std::move(v); };
  return f;
}

/// A nested struct member with a SchemaOf of its own.
template <auto Member>
[[nodiscard]] constexpr SchemaField object_field(std::string_view name, FieldText text) {
  using T = schema_detail::type_t<Member>;
  SchemaField f{
      .name = name, .kind = FieldKind::object, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.nested = [] { return &SchemaOf<T>::get(); };
  f.get_object = [](const void* o) -> const void* { return &schema_detail::cref<Member>(o); };
  f.mutable_object = [](void* o) -> void* { return &schema_detail::ref<Member>(o); };
  return f;
}

/// A std::optional member of a struct with a SchemaOf of its own: JSON null when empty.
template <auto Member>
[[nodiscard]] constexpr SchemaField optional_object_field(std::string_view name, FieldText text) {
  using T = typename schema_detail::type_t<Member>::value_type;
  SchemaField f{
      .name = name, .kind = FieldKind::object, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.nullable = true;
  f.nested = [] { return &SchemaOf<T>::get(); };
  f.get_object = [](const void* o) -> const void* {
    const auto& member = schema_detail::cref<Member>(o);
    return member ? &*member : nullptr;
  };
  f.mutable_object = [](void* o) -> void* {
    auto& member = schema_detail::ref<Member>(o);
    return member ? &*member : nullptr;
  };
  f.has_object = [](const void* o) { return schema_detail::cref<Member>(o).has_value(); };
  f.emplace_object = [](void* o) -> void* { return &schema_detail::ref<Member>(o).emplace(); };
  f.reset_object = [](void* o) { schema_detail::ref<Member>(o).reset(); };
  return f;
}

/// A std::variant member whose i-th alternative is named by the i-th value of enumeration `E`, written in the
/// alternative's object under the key `tag` ({"mode": "fading", "gain": 0.5}). Each alternative has a
/// SchemaOf.
template <auto Member, typename E>
[[nodiscard]] constexpr SchemaField variant_field(std::string_view name, std::string_view tag,
                                                  FieldText text) {
  using V = schema_detail::type_t<Member>;
  SchemaField f{
      .name = name, .kind = FieldKind::variant, .unit = text.unit, .doc = text.doc, .source = text.source};
  f.variant_tag = tag;
  f.spellings = [] { return enum_spellings<E>(); };
  f.enum_name = EnumTable<E>::name;
  f.variant_schema = [](std::size_t index) { return schema_detail::alternative_schema<V>(index); };
  f.variant_index = [](const void* o) -> std::size_t { return schema_detail::cref<Member>(o).index(); };
  f.variant_get = [](const void* o) -> const void* {
    return std::visit([](const auto& held) -> const void* { return &held; }, schema_detail::cref<Member>(o));
  };
  f.variant_emplace = [](void* o, std::size_t index) -> void* {
    auto& member = schema_detail::ref<Member>(o);
    member = schema_detail::default_alternative<V>(index);
    return std::visit([](auto& held) -> void* { return &held; }, member);
  };
  return f;
}

/// A std::vector member of structs with a SchemaOf of their own.
template <auto Member>
[[nodiscard]] constexpr SchemaField object_list_field(std::string_view name, FieldText text) {
  using T = typename schema_detail::type_t<Member>::value_type;
  SchemaField f{.name = name,
                .kind = FieldKind::object_list,
                .unit = text.unit,
                .doc = text.doc,
                .source = text.source};
  f.option = text.option;
  f.option_value_name = text.option_value_name;
  f.nested = [] { return &SchemaOf<T>::get(); };
  f.list_size = [](const void* o) -> std::size_t { return schema_detail::cref<Member>(o).size(); };
  f.list_at = [](const void* o, std::size_t i) -> const void* { return &schema_detail::cref<Member>(o)[i]; };
  f.list_append = [](void* o) -> void* { return &schema_detail::ref<Member>(o).emplace_back(); };
  f.list_clear = [](void* o) { schema_detail::ref<Member>(o).clear(); };
  return f;
}

/// A fixed-length vector member indexed with [] (Vec2, Vec3), each element in `range`.
template <auto Member, std::size_t N>
[[nodiscard]] constexpr SchemaField number_array_field(std::string_view name, ParameterRange range,
                                                       FieldText text) {
  SchemaField f{.name = name,
                .kind = FieldKind::number_array,
                .unit = text.unit,
                .doc = text.doc,
                .source = text.source};
  f.range = range;
  f.array_size = N;
  f.get_number = [](const SchemaField&, const void* o, std::size_t i) -> double {
    return schema_detail::cref<Member>(o)[static_cast<long>(i)];
  };
  f.set_number = [](const SchemaField&, void* o, std::size_t i, double v) {
    schema_detail::ref<Member>(o)[static_cast<long>(i)] = v;
  };
  return f;
}

/// A field added in document version `version` (see SchemaField::since_version).
[[nodiscard]] constexpr SchemaField since(int version, SchemaField field) {
  field.since_version = version;
  return field;
}

/// A field any version of a document may lack (see SchemaField::omissible).
[[nodiscard]] constexpr SchemaField omissible(SchemaField field) {
  field.omissible = true;
  return field;
}

/// A string field whose text must match `pattern` (SchemaField::pattern).
[[nodiscard]] constexpr SchemaField with_pattern(std::string_view pattern, SchemaField field) {
  field.pattern = pattern;
  return field;
}

/// A string field of at least `characters` characters (SchemaField::min_length).
[[nodiscard]] constexpr SchemaField with_min_length(std::size_t characters, SchemaField field) {
  field.min_length = characters;
  return field;
}

/// A list field of `fewest` to `most` elements (SchemaField::min_items, max_items).
[[nodiscard]] constexpr SchemaField with_item_count(std::size_t fewest, std::size_t most, SchemaField field) {
  field.min_items = fewest;
  field.max_items = most;
  return field;
}

/// The command line gives the field in another unit: option value = field value x `factor`.
[[nodiscard]] constexpr SchemaField option_in(std::string_view unit, double factor, SchemaField field) {
  field.option_unit = unit;
  field.option_factor = factor;
  return field;
}

/// The command line gives the field as a whole number of another unit (integer syntax, "0..60000" in help):
/// option value = field value x `factor`.
[[nodiscard]] constexpr SchemaField option_in_whole(std::string_view unit, double factor, SchemaField field) {
  field = option_in(unit, factor, field);
  field.option_whole = true;
  return field;
}

/// An `option_in_whole` field's range as whole numbers of its option's unit ("0..60000").
[[nodiscard]] std::string whole_option_range_text(const SchemaField& field);

/// The numeric fields of a struct's ParameterTable as schema fields, in table order: the table stays the one
/// definition of their ranges.
template <typename S>
[[nodiscard]] std::vector<SchemaField> table_fields() {
  std::vector<SchemaField> out;
  const auto entries = ParameterTable<S>::fields();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    SchemaField f{
        .name = entries[i].name, .kind = FieldKind::number, .unit = entries[i].unit, .doc = entries[i].doc};
    f.range = entries[i].range;
    f.table_slot = i;
    f.get_number = [](const SchemaField& self, const void* o, std::size_t) -> double {
      return static_cast<const S*>(o)->*(ParameterTable<S>::fields()[self.table_slot].member);
    };
    f.set_number = [](const SchemaField& self, void* o, std::size_t, double v) {
      static_cast<S*>(o)->*(ParameterTable<S>::fields()[self.table_slot].member) = v;
    };
    if (entries[i].whole_number) make_whole_number_kind(f);
    out.push_back(f);
  }
  return out;
}

/// The default instance of `S` for `Schema::defaults`.
template <typename S>
[[nodiscard]] const void* default_of();

/// The schema of a struct its ParameterTable describes whole (every field a number), with `rules` (may be
/// null) as its rules between fields. Built once per struct.
template <typename S>
[[nodiscard]] const Schema& table_schema(std::string_view doc, void (*rules)(const void*) = nullptr) {
  static const std::vector<SchemaField> fields = table_fields<S>();
  static const Schema schema{.name = ParameterTable<S>::name,
                             .doc = doc,
                             .fields = fields,
                             .defaults = default_of<S>,
                             .check_rules = rules};
  return schema;
}

/// The default instance of `S` for `Schema::defaults`.
template <typename S>
[[nodiscard]] const void* default_of() {
  static const S value{};
  return &value;
}

/// `S::validate` as `Schema::check_rules`.
template <typename S>
void validate_of(const void* object) {
  static_cast<const S*>(object)->validate();
}

[[noreturn]] void throw_not_a_spelling(std::string_view text, std::span<const std::string_view> spellings);

template <typename E>
E parse_enum(std::string_view text) {
  if (const std::optional<E> value = enum_from_spelling<E>(text)) return *value;
  throw_not_a_spelling(text, enum_spellings<E>());
}

}  // namespace calligraphy
