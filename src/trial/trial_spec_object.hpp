#pragma once
// The trial specification read from a JSON object that is part of a larger document (a record's
// specification), so that its errors name the member's whole pointer. Internal.
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy::trial_detail {

/// `trial_spec_from_json` of the object at `pointer` in a document read from `source`: DataError naming the
/// source and the value's pointer, then InvalidArgument naming the field (TrialSpec::validate).
Checked<TrialSpec> trial_spec_from_object(const nlohmann::json& object, const std::string& pointer,
                                          const std::string& source, TeacherSource teacher_from);

}  // namespace calligraphy::trial_detail
