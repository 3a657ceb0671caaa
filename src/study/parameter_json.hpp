#pragma once
// A parameter struct as a JSON object and back, field by field as its table names them (parameter_table.hpp):
// numbers as JSON numbers (a double prints with 17 significant digits and reads back to the same bits), no
// text in between, and no range written here: the struct's own validate() checks what was read. Internal.
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "calligraphy/core/parameter_table.hpp"
#include "core/json_reader.hpp"

namespace calligraphy::study_detail {

/// Every numeric field of `object`'s table, by name, into `out`.
template <typename S>
void put_parameters(nlohmann::json& out, const S& object) {
  for (const ParameterField<S>& field : ParameterTable<S>::fields())
    out[std::string(field.name)] = object.*field.member;
}

/// Every numeric field of `S`'s table read from `reader` into `object`, each required and a finite number;
/// throws DataError naming the source and the member's pointer. The ranges are the caller's to check
/// (the struct's validate()).
template <typename S>
void take_parameters(json_detail::ObjectReader& reader, S& object) {
  constexpr double kLargest = std::numeric_limits<double>::max();
  for (const ParameterField<S>& field : ParameterTable<S>::fields())
    object.*field.member = reader.number(std::string(field.name), -kLargest, kLargest);
}

/// The value of `member` (an entry of `S`'s table) read from `reader` under `key`, the file's own name for
/// it, or `fallback` when the key is absent: a finite number within the table's range, the one definition
/// of it. Throws DataError naming the source and the pointer, with the range and the field it is.
template <typename S>
double table_number_or(json_detail::ObjectReader& reader, const std::string& key, double fallback,
                       double S::*member) {
  constexpr double kLargest = std::numeric_limits<double>::max();
  const ParameterField<S>& field = parameter_field(member);
  if (!reader.has(key)) return fallback;
  const double value = reader.number(key, -kLargest, kLargest);
  if (!field.range.contains(value)) {
    json_detail::fail(reader.source(), reader.pointer(key),
                      "expected a number " + field.range.text(field.unit) + " (" +
                          std::string(ParameterTable<S>::name) + "." + std::string(field.name) + "), got " +
                          nlohmann::json(value).dump());
  }
  return value;
}

/// As table_number_or, for a value the file may leave out: unchanged when the key is absent.
template <typename S>
void take_table_number(json_detail::ObjectReader& reader, const std::string& key, std::optional<double>& out,
                       double S::*member) {
  if (reader.has(key)) out = table_number_or(reader, key, 0.0, member);
}

}  // namespace calligraphy::study_detail
