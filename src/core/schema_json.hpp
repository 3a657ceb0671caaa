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

}  // namespace calligraphy::schema_detail
