// The JSON half of the schema (schema.hpp): a struct to JSON and back, strictly, and its JSON Schema.
#include "core/schema_json.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"
#include "core/json_reader.hpp"
#include "core/utc_time.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

ordered_json value_json(const SchemaField& field, const void* object) {
  switch (field.kind) {
    case FieldKind::number:
      return field.get_number(field, object, 0);
    case FieldKind::number_array: {
      ordered_json out = ordered_json::array();
      for (std::size_t i = 0; i < field.array_size; ++i) out.push_back(field.get_number(field, object, i));
      return out;
    }
    case FieldKind::integer:
      if (field.integer_unsigned) return field.get_unsigned(object);
      return field.integer_value(object);
    case FieldKind::boolean:
      return field.get_boolean(object);
    case FieldKind::enumeration:
      return std::string(field.spellings()[field.get_choice(object)]);
    case FieldKind::string:
      return field.get_string(object);
    case FieldKind::object: {
      const void* nested = field.get_object(object);
      if (nested == nullptr) return nullptr;
      return schema_detail::to_json(*field.nested(), nested);
    }
    case FieldKind::variant: {
      const std::size_t index = field.variant_index(object);
      ordered_json out = ordered_json::object();
      out[std::string(field.variant_tag)] = std::string(field.spellings()[index]);
      const ordered_json alternative =
          schema_detail::to_json(*field.variant_schema(index), field.variant_get(object));
      for (auto item = alternative.begin(); item != alternative.end(); ++item) out[item.key()] = item.value();
      return out;
    }
    case FieldKind::object_list: {
      ordered_json out = ordered_json::array();
      for (std::size_t i = 0; i < field.list_size(object); ++i)
        out.push_back(schema_detail::to_json(*field.nested(), field.list_at(object, i)));
      return out;
    }
  }
  return nullptr;
}

// A number member: finite, in the field's range; the error names the pointer and the field as "Struct.field".
double read_number(const SchemaField& field, const std::string& owner, const json& value,
                   const std::string& pointer, const std::string& source) {
  if (!value.is_number())
    json_detail::fail(source, pointer, "expected a number, got " + json_detail::describe(value));
  const double number = value.get<double>();
  if (!field.range.contains(number)) {
    json_detail::fail(source, pointer,
                      "expected a number " + field.range.text(field.unit) + " (" + owner + "." +
                          std::string(field.name) + "), got " + json_detail::describe(value));
  }
  return number;
}

void read_value(const SchemaField& field, const std::string& owner, void* object, const json& value,
                const std::string& pointer, const std::string& source, const SchemaReadOptions& options,
                SchemaReadResult& result) {
  const auto expect = [&](bool ok, const std::string& what) {
    if (!ok) json_detail::fail(source, pointer, "expected " + what + ", got " + json_detail::describe(value));
  };
  switch (field.kind) {
    case FieldKind::number:
      field.set_number(field, object, 0, read_number(field, owner, value, pointer, source));
      return;
    case FieldKind::number_array:
      expect(value.is_array() && value.size() == field.array_size,
             "an array of " + std::to_string(field.array_size) + " numbers");
      for (std::size_t i = 0; i < field.array_size; ++i) {
        field.set_number(field, object, i,
                         read_number(field, owner, value[i], json_detail::child_pointer(pointer, i), source));
      }
      return;
    case FieldKind::integer:
      if (field.integer_unsigned) {
        // Digits, or exponent form when exact (1e3), as every integer of a file is read.
        field.set_unsigned(object, json_detail::as_unsigned(value, pointer, source));
        return;
      }
      field.set_integer_value(
          object, json_detail::as_integer(value, pointer, source, field.integer_low, field.integer_high));
      return;
    case FieldKind::boolean:
      expect(value.is_boolean(), "true or false");
      field.set_boolean(object, value.get<bool>());
      return;
    case FieldKind::enumeration: {
      const auto spellings = field.spellings();
      const std::string choices =
          "one of " + join_spellings(spellings, ", ", "\"") + " (" + std::string(field.enum_name) + ")";
      expect(value.is_string(), choices);
      const auto& text = value.get_ref<const std::string&>();
      for (std::size_t i = 0; i < spellings.size(); ++i) {
        if (spellings[i] == text) {
          field.set_choice(object, i);
          return;
        }
      }
      expect(false, choices);
      return;
    }
    case FieldKind::string: {
      std::string text = json_detail::as_string(value, pointer, source);
      try {
        field.check_string(text);
      } catch (const InvalidArgument& e) {
        json_detail::fail(source, pointer, e.what());
      }
      field.set_string(object, std::move(text));
      return;
    }
    case FieldKind::object: {
      if (field.nullable && value.is_null()) {
        field.reset_object(object);
        return;
      }
      void* nested = field.nullable ? field.emplace_object(object) : field.mutable_object(object);
      schema_detail::from_json(*field.nested(), nested, value, pointer, source, options, result);
      return;
    }
    case FieldKind::variant: {
      const std::string tag(field.variant_tag);
      const auto spellings = field.spellings();
      expect(value.is_object() && value.contains(tag) && value[tag].is_string(),
             "an object with \"" + tag + "\" one of " + join_spellings(spellings, ", ", "\""));
      const auto& name = value[tag].get_ref<const std::string&>();
      std::size_t index = spellings.size();
      for (std::size_t i = 0; i < spellings.size(); ++i) {
        if (spellings[i] == name) index = i;
      }
      if (index == spellings.size()) {
        json_detail::fail(source, json_detail::child_pointer(pointer, tag),
                          "expected one of " + join_spellings(spellings, ", ", "\"") + ", got " +
                              json_detail::describe(value[tag]));
      }
      json rest = value;
      rest.erase(tag);
      schema_detail::from_json(*field.variant_schema(index), field.variant_emplace(object, index), rest,
                               pointer, source, options, result);
      return;
    }
    case FieldKind::object_list:
      expect(value.is_array(), "an array of objects");
      field.list_clear(object);
      // An element of a list has no default to fall back on: each states every field.
      for (std::size_t i = 0; i < value.size(); ++i) {
        schema_detail::from_json(*field.nested(), field.list_append(object), value[i],
                                 json_detail::child_pointer(pointer, i), source,
                                 {.require_all = true, .version = options.version}, result);
      }
      return;
  }
}

// The JSON Schema of one field's value; nested structs as references into `defs`.
ordered_json field_schema(const SchemaField& field, const void* defaults, ordered_json& defs,
                          bool all_required);

ordered_json number_schema(const ParameterRange& range) {
  ordered_json out = {{"type", "number"}};
  if (range.low_open) {
    out["exclusiveMinimum"] = range.low;
  } else {
    out["minimum"] = range.low;
  }
  if (std::isfinite(range.high)) {
    if (range.high_open) {
      out["exclusiveMaximum"] = range.high;
    } else {
      out["maximum"] = range.high;
    }
  }
  return out;
}

std::string describe_field(const SchemaField& field) {
  std::string out(field.doc);
  if (!field.unit.empty()) out += " [" + std::string(field.unit) + "]";
  if (!field.source.empty()) out += " (" + std::string(field.source) + ")";
  return out;
}

ordered_json struct_schema(const Schema& schema, ordered_json& defs, bool all_required) {
  ordered_json out = {{"type", "object"}, {"description", std::string(schema.doc)}};
  ordered_json properties = ordered_json::object();
  ordered_json required = ordered_json::array();
  const void* defaults = schema.defaults();
  for (const SchemaField& field : schema.fields) {
    properties[std::string(field.name)] = field_schema(field, defaults, defs, all_required);
    if (all_required && field.since_version == 0 && !field.omissible)
      required.push_back(std::string(field.name));
  }
  out["properties"] = std::move(properties);
  out["additionalProperties"] = false;
  // A record holds every field (SchemaReadOptions::require_all); a file a person writes may leave out what
  // keeps its default.
  if (all_required) out["required"] = std::move(required);
  return out;
}

// The versions in which fields were added anywhere in `schema` (SchemaField::since_version), through its
// objects and lists of objects; `seen` guards a struct met inside itself.
void added_versions(const Schema& schema, std::set<int>& versions, std::set<const Schema*>& seen) {
  if (!seen.insert(&schema).second) return;
  for (const SchemaField& field : schema.fields) {
    if (field.since_version > 0 && !field.omissible) versions.insert(field.since_version);
    if (field.kind == FieldKind::object || field.kind == FieldKind::object_list)
      added_versions(*field.nested(), versions, seen);
  }
}

// What a document of `version` or later must hold that an older one may lack: the fields added in `version`
// where they are, as a JSON Schema (`required` at each level, `properties` down to it); empty when none.
ordered_json added_in(const Schema& schema, int version, std::set<const Schema*>& path) {
  ordered_json out = ordered_json::object();
  if (!path.insert(&schema).second) return out;
  ordered_json required = ordered_json::array();
  ordered_json properties = ordered_json::object();
  for (const SchemaField& field : schema.fields) {
    if (field.since_version == version && !field.omissible) required.push_back(std::string(field.name));
    if (field.kind != FieldKind::object && field.kind != FieldKind::object_list) continue;
    ordered_json nested = added_in(*field.nested(), version, path);
    if (nested.empty()) continue;
    properties[std::string(field.name)] =
        field.kind == FieldKind::object ? nested : ordered_json{{"items", std::move(nested)}};
  }
  path.erase(&schema);
  if (!required.empty()) out["required"] = std::move(required);
  if (!properties.empty()) out["properties"] = std::move(properties);
  return out;
}

std::string def_reference(const Schema& schema, ordered_json& defs, bool all_required) {
  const std::string name(schema.name);
  if (!defs.contains(name)) {
    defs[name] = nullptr;  // placed first: a struct met again inside itself refers to it
    defs[name] = struct_schema(schema, defs, all_required);
  }
  return "#/$defs/" + name;
}

ordered_json field_schema(const SchemaField& field, const void* defaults, ordered_json& defs,
                          bool all_required) {
  ordered_json out;
  switch (field.kind) {
    case FieldKind::number:
      out = number_schema(field.range);
      break;
    case FieldKind::number_array:
      out = {{"type", "array"},
             {"items", number_schema(field.range)},
             {"minItems", field.array_size},
             {"maxItems", field.array_size}};
      break;
    case FieldKind::integer:
      out = {{"type", "integer"}};
      if (field.integer_unsigned) {
        out["minimum"] = 0;
        out["maximum"] = std::numeric_limits<std::uint64_t>::max();
      } else {
        out["minimum"] = field.integer_low;
        out["maximum"] = field.integer_high;
      }
      break;
    case FieldKind::boolean:
      out = {{"type", "boolean"}};
      break;
    case FieldKind::enumeration: {
      out = {{"type", "string"}, {"title", std::string(field.enum_name)}};
      ordered_json values = ordered_json::array();
      for (const std::string_view spelling : field.spellings()) values.push_back(std::string(spelling));
      out["enum"] = std::move(values);
      break;
    }
    case FieldKind::string:
      out = {{"type", "string"}};
      if (field.string_format == StringFormat::utc_time) {
        out["format"] = "date-time";  // RFC 3339's, narrowed by the pattern to UTC with a Z
        out["pattern"] = std::string(kUtcTimePattern);
      }
      if (field.string_format == StringFormat::sha256) out["pattern"] = "^([0-9a-f]{64})?$";
      if (field.string_format == StringFormat::constant) out["const"] = value_json(field, defaults);
      if (field.min_length > 0) out["minLength"] = field.min_length;
      if (!field.pattern.empty()) out["pattern"] = std::string(field.pattern);
      break;
    case FieldKind::object:
      out = {{"$ref", def_reference(*field.nested(), defs, all_required)}};
      if (field.nullable) out = {{"anyOf", ordered_json::array({out, {{"type", "null"}}})}};
      break;
    case FieldKind::variant: {
      ordered_json choices = ordered_json::array();
      const auto spellings = field.spellings();
      for (std::size_t i = 0; i < spellings.size(); ++i) {
        ordered_json alternative = struct_schema(*field.variant_schema(i), defs, all_required);
        ordered_json properties = {{std::string(field.variant_tag), {{"const", std::string(spellings[i])}}}};
        for (auto& [key, value] : alternative["properties"].items()) properties[key] = value;
        alternative["properties"] = std::move(properties);
        ordered_json required = ordered_json::array({std::string(field.variant_tag)});
        if (alternative.contains("required")) {
          for (const auto& key : alternative["required"]) required.push_back(key);
        }
        alternative["required"] = std::move(required);
        choices.push_back(std::move(alternative));
      }
      out = {{"title", std::string(field.enum_name)}, {"oneOf", std::move(choices)}};
      break;
    }
    case FieldKind::object_list:
      out = {{"type", "array"}, {"items", {{"$ref", def_reference(*field.nested(), defs, all_required)}}}};
      if (field.min_items > 0) out["minItems"] = field.min_items;
      if (field.max_items != std::numeric_limits<std::size_t>::max()) out["maxItems"] = field.max_items;
      break;
  }
  out["description"] = describe_field(field);
  // A default is what a key left out means, so it is stated only when it is a value the field takes: an
  // empty time or id, a plan that must hold a trial, a count whose 0 means "none" have none to state.
  if (field.kind != FieldKind::variant && (field.kind != FieldKind::object || field.nullable) &&
      field.holds_valid_value(defaults))
    out["default"] = value_json(field, defaults);
  return out;
}

}  // namespace

namespace schema_detail {

ordered_json to_json(const Schema& schema, const void* object) {
  ordered_json out = ordered_json::object();
  for (const SchemaField& field : schema.fields) out[std::string(field.name)] = value_json(field, object);
  return out;
}

void read_field(const Schema& schema, const SchemaField& field, void* object, const json& value,
                const std::string& pointer, const std::string& source) {
  SchemaReadResult unused;
  read_value(field, std::string(schema.name), object, value, pointer, source, {}, unused);
}

ordered_json field_json_schema(const SchemaField& field, const void* defaults) {
  ordered_json defs = ordered_json::object();  // a scalar refers to no struct
  return field_schema(field, defaults, defs, false);
}

void from_json(const Schema& schema, void* object, const json& document, const std::string& pointer,
               const std::string& source, const SchemaReadOptions& options, SchemaReadResult& result) {
  if (!document.is_object()) {
    json_detail::fail(
        source, pointer.empty() ? "/" : pointer,
        "expected an object (" + std::string(schema.name) + "), got " + json_detail::describe(document));
  }
  const std::string owner(schema.name);
  for (const auto& [key, value] : document.items()) {
    if (schema.field(key) == nullptr || schema.field(key)->name != key) {
      std::string names;
      for (const SchemaField& field : schema.fields)
        names += (names.empty() ? "" : ", ") + std::string(field.name);
      json_detail::fail(source, json_detail::child_pointer(pointer, key),
                        "unknown key (" + owner + " has " + names + ")");
    }
  }
  for (const SchemaField& field : schema.fields) {
    const std::string key(field.name);
    const std::string at = json_detail::child_pointer(pointer, key);
    const auto found = document.find(key);
    if (found == document.end()) {
      if (options.require_all && field.since_version <= options.version && !field.omissible) {
        json_detail::fail(source, at, "missing (" + owner + "." + key + ": " + field.description() + ")");
      }
      if (options.require_all) result.defaulted.push_back(at);
      continue;
    }
    if (found->is_null() && !field.nullable) {
      json_detail::fail(source, at,
                        "null is not a value (" + owner + "." + key + ": " + field.description() + ")");
    }
    if (field.string_format == StringFormat::constant && schema.defaults != nullptr) {
      const std::string& expected = field.get_string(schema.defaults());
      if (!found->is_string() || found->get_ref<const std::string&>() != expected)
        json_detail::fail(source, at, "expected \"" + expected + "\", got " + json_detail::describe(*found));
    }
    read_value(field, owner, object, *found, at, source, options, result);
  }
  if (schema.check_rules != nullptr) {
    try {
      schema.check_rules(object);
    } catch (const InvalidArgument& e) {
      json_detail::fail(source, pointer.empty() ? "/" : pointer, e.what());
    }
  }
}

}  // namespace schema_detail

std::string schema_json(const Schema& schema, const void* object) {
  return schema_detail::to_json(schema, object).dump(2) + "\n";
}

SchemaReadResult schema_from_json(const Schema& schema, void* object, std::string_view text,
                                  const std::string& source, const SchemaReadOptions& options) {
  SchemaReadResult result;
  schema_detail::from_json(schema, object, json_detail::parse_json(text, source), "", source, options,
                           result);
  return result;
}

std::string json_schema_text(const Schema& schema, std::string_view id, std::string_view title,
                             bool all_required) {
  ordered_json defs = ordered_json::object();
  ordered_json root = {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
                       {"$id", std::string(id)},
                       {"title", std::string(title)}};
  ordered_json body = struct_schema(schema, defs, all_required);
  for (auto& [key, value] : body.items()) root[key] = value;
  // A document that holds every field (a record) holds those its version has: one condition on the root's
  // `version` per version that added fields, requiring them where they are, as the reader does
  // (SchemaReadOptions::version).
  if (all_required && schema.field("version") != nullptr) {
    std::set<int> versions;
    std::set<const Schema*> seen;
    added_versions(schema, versions, seen);
    ordered_json conditions = ordered_json::array();
    for (const int version : versions) {
      std::set<const Schema*> path;
      conditions.push_back({{"if",
                             {{"properties", {{"version", {{"minimum", version}}}}},
                              {"required", ordered_json::array({"version"})}}},
                            {"then", added_in(schema, version, path)}});
    }
    if (!conditions.empty()) root["allOf"] = std::move(conditions);
  }
  if (!defs.empty()) root["$defs"] = std::move(defs);
  return root.dump(2) + "\n";
}

}  // namespace calligraphy
