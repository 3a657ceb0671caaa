#pragma once
// The trial specification read from a JSON object that is part of a larger document (a record's
// specification), so that its errors name the member's whole pointer. Internal.
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy::trial_detail {

/// Records before the writer's settings were typed wrote them as "key=value" strings: each turned into a
/// {"key", "value"} object in place, in the specification object `trial` at `pointer`. Throws DataError
/// naming the setting's pointer when a string is not "key=number".
void type_writer_settings(nlohmann::json& trial, const std::string& pointer, const std::string& source);

/// `trial_spec_from_json` of the object at `pointer` in a document read from `source`, missing members as
/// `options` say (a person's file: their defaults; a record: required): DataError naming the source and the
/// value's pointer, then InvalidArgument naming the field (TrialSpec::validate).
Checked<TrialSpec> trial_spec_from_object(const nlohmann::json& object, const std::string& pointer,
                                          const std::string& source, TeacherSource teacher_from,
                                          const SchemaReadOptions& options = {});

}  // namespace calligraphy::trial_detail
