#pragma once
// A parameter struct as a JSON object and back, field by field as its table names them (parameter_table.hpp):
// numbers as JSON numbers (a double prints with 17 significant digits and reads back to the same bits), no
// text in between, and no range written here: the struct's own validate() checks what was read. Internal.
#include <limits>
#include <nlohmann/json.hpp>

#include "calligraphy/render/parameter_table.hpp"
#include "study/json_reader.hpp"

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
void take_parameters(ObjectReader& reader, S& object) {
  constexpr double kLargest = std::numeric_limits<double>::max();
  for (const ParameterField<S>& field : ParameterTable<S>::fields())
    object.*field.member = reader.number(std::string(field.name), -kLargest, kLargest);
}

}  // namespace calligraphy::study_detail
