#pragma once
// The schema's JSON form on nlohmann's values (schema.hpp has the text form), for readers that hold a
// document already: a trial record's parts, a protocol's. Internal.
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/core/schema.hpp"

namespace calligraphy::schema_detail {

/// `object` as a JSON object, keys in field order.
nlohmann::ordered_json to_json(const Schema& schema, const void* object);

/// Reads `document` (at `pointer` of `source`) into `object`, as schema_from_json does.
void from_json(const Schema& schema, void* object, const nlohmann::json& document, const std::string& pointer,
               const std::string& source, const SchemaReadOptions& options, SchemaReadResult& result);

/// Reads one member's `value` (at `pointer` of `source`) into field `field` of `object` (described by
/// `schema`): its type, range or spellings checked as `from_json` checks them, the error naming the pointer.
/// For a reader that takes some members of an object through a schema and others by hand.
void read_field(const Schema& schema, const SchemaField& field, void* object, const nlohmann::json& value,
                const std::string& pointer, const std::string& source);

/// The JSON Schema of one scalar field (number, integer, boolean, enumeration, string) of a struct whose
/// default instance is `defaults`: type, range or `enum`, description and default.
nlohmann::ordered_json field_json_schema(const SchemaField& field, const void* defaults);

}  // namespace calligraphy::schema_detail
